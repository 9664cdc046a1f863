"""Least-squares polynomial fits for gonio::numerics (see the end of this file)."""
import math
def cheb_basis(u, n):
    T=[1.0,u]
    for k in range(2,n+1): T.append(2*u*T[-1]-T[-2])
    return T[:n+1]
def solve(A,b):
    n=len(b); M=[row[:]+[b[i]] for i,row in enumerate(A)]
    for c in range(n):
        p=max(range(c,n),key=lambda r:abs(M[r][c])); M[c],M[p]=M[p],M[c]
        for r in range(n):
            if r!=c:
                f=M[r][c]/M[c][c]
                for k in range(c,n+1): M[r][k]-=f*M[c][k]
    return [M[i][n]/M[i][i] for i in range(n)]
def fit(f, lo, hi, deg, npts=3000, iters=30):
    us=[math.cos(math.pi*(i+0.5)/npts) for i in range(npts)]
    xs=[lo+(u+1)/2*(hi-lo) for u in us]
    ys=[f(x) for x in xs]
    w=[1.0]*npts
    for it in range(iters):
        A=[[0.0]*(deg+1) for _ in range(deg+1)]; b=[0.0]*(deg+1)
        for u,y,wi in zip(us,ys,w):
            T=cheb_basis(u,deg)
            for i in range(deg+1):
                b[i]+=wi*T[i]*y
                for j in range(deg+1): A[i][j]+=wi*T[i]*T[j]
        c=solve(A,b)
        errs=[abs(sum(ci*Ti for ci,Ti in zip(c,cheb_basis(u,deg)))-y) for u,y in zip(us,ys)]
        s=sum(wi*e for wi,e in zip(w,errs))
        w=[wi*e/s*npts for wi,e in zip(w,errs)]  # Lawson
    # chebyshev -> monomial in u
    mono=[0.0]*(deg+1)
    Tm=[[1.0],[0.0,1.0]]
    for k in range(2,deg+1):
        a=[0.0]+[2*v for v in Tm[-1]]; bb=Tm[-2]+[0.0]*(len(a)-len(Tm[-2]))
        Tm.append([x-y for x,y in zip(a,bb)])
    for ci,Tk in zip(c,Tm[:deg+1]):
        for i,v in enumerate(Tk): mono[i]+=ci*v
    return mono, max(errs)


# The fits behind gonio::numerics (f32 lane approximations), reproducible with plain Python 3:
#   python3 tools/fit_special_functions.py
# Each is a weighted least-squares fit in the Chebyshev basis of [-1, 1] whose weights are updated by
# Lawson's rule (towards the minimax fit), printed as monomial coefficients in the mapped variable u.
if __name__ == "__main__":
    SQRT_PI = math.sqrt(math.pi)

    def erfcx(x):
        if x < 25:
            return math.erfc(x) * math.exp(x * x)
        s, term, k = 0.0, 1.0, 0
        while abs(term) > 1e-18:
            s += term
            k += 1
            term *= -(2 * k - 1) / (2 * x * x)
        return s / (x * SQRT_PI)

    def erfinv(y):
        x = 0.0 if y == 0 else math.copysign(math.sqrt(-math.log((1 - abs(y)) * (1 + abs(y)))), y) * 0.8
        for _ in range(100):
            f = -(math.erfc(x) - (1 - y)) if y > 0.5 else math.erf(x) - y
            nx = x - f / (2 / SQRT_PI * math.exp(-x * x))
            if abs(nx - x) < 1e-16 * max(1, abs(x)):
                return nx
            x = nx
        return x

    # erfc(x) = t exp(-x^2 + P(t)), t = 2/(2 + x), x in [0, 10]: P on t in [1/6, 1].
    print("erfc P", fit(lambda t: math.log(erfcx(2 / t - 2) / t), 1 / 6, 1.0, 10))

    # erfinv(y) = y P(w), w = -ln(1 - y^2) < 5; y Q(sqrt(w) - 3) beyond.
    def over_y(w):
        if w < 1e-12:
            return SQRT_PI / 2
        y = math.sqrt(-math.expm1(-w))
        return erfinv(y) / y
    print("erfinv central", fit(over_y, 0.0, 5.0, 9, npts=1500, iters=20))
    print("erfinv tail", fit(lambda s: over_y((s + 3) ** 2), math.sqrt(5) - 3, 1.0, 9, npts=1500, iters=20))

    # Beckmann: 1 - a sqrt(pi) erfcx(a) = h(1/a^2) / (2 a^2), a >= 2.5.
    def one_minus(a):
        if a < 20:
            return 1 - a * SQRT_PI * erfcx(a)
        s, term, k = 0.0, 1.0, 0
        while True:
            k += 1
            term *= -(2 * k - 1) / (2 * a * a)
            if abs(term) < 1e-20:
                return s
            s -= term
    print("lambda h", fit(lambda v: 1.0 if v == 0 else 2 / v * one_minus(1 / math.sqrt(v)), 0.0, 1 / 2.5 ** 2, 8, npts=1500, iters=20))

    # Beckmann: k(a) = a e^{a^2} Lambda(a) = (1/sqrt(pi) - a erfcx(a))/2 on a in [0, 2.5], u = a/1.25 - 1.
    print("beckmann lambda k", fit(lambda a: (1 / SQRT_PI - a * erfcx(a)) / 2, 0.0, 2.5, 14, npts=2000, iters=30))
