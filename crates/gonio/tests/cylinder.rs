//! The `cylinder` shape against closed forms: ray hits against the quadratic solved in f64 in world space,
//! normals, uv, area, bounds, area sampling (the solid angle an open cylinder subtends at its centre), and
//! the errors for parameters that make no cylinder.

use glam::{DVec3, Vec2};
use gonio::geometry::cylinder::{Cylinder, CylinderError};
use gonio::geometry::{Ray, Shape};
use gonio::math::{Transform, Vec3};
use gonio::sampling::Pcg32;
use gonio::scene::{mitsuba_xml, Scene};
use std::f64::consts::PI;
use std::path::Path;

/// A cylinder given by its world-space centre line c0 → c0 + L e (e unit) and radius r, in f64.
struct Exact {
    c0: DVec3,
    e: DVec3,
    len: f64,
    r: f64,
}

impl Exact {
    /// The first hit in (0, ∞) of o + t d within 0 ≤ z ≤ L (the near root, else the far one), and whether
    /// the case is clear of the edges and grazing rays (where f32 and f64 may rightly disagree).
    fn hit(&self, o: DVec3, d: DVec3) -> (Option<f64>, bool) {
        let w = o - self.c0;
        let (dp, wp) = (d - self.e * d.dot(self.e), w - self.e * w.dot(self.e));
        let (a, b, c) = (dp.dot(dp), 2.0 * dp.dot(wp), wp.dot(wp) - self.r * self.r);
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return (None, disc < -1e-3 * a);
        }
        let (t0, t1) = ((-b - disc.sqrt()) / (2.0 * a), (-b + disc.sqrt()) / (2.0 * a));
        let z = |t: f64| (w + d * t).dot(self.e);
        let clear = |t: f64| (z(t).abs() > 1e-3 && (z(t) - self.len).abs() > 1e-3) && t.abs() > 1e-3;
        let inside = |t: f64| t > 0.0 && z(t) >= 0.0 && z(t) <= self.len;
        let ok = disc > 1e-3 * a && clear(t0) && clear(t1);
        (
            if inside(t0) {
                Some(t0)
            } else if inside(t1) {
                Some(t1)
            } else {
                None
            },
            ok,
        )
    }
}

fn random_unit(rng: &mut Pcg32) -> Vec3 {
    loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        if v.length_squared() > 1e-2 && v.length_squared() < 1.0 {
            return v.normalize();
        }
    }
}

/// Random cylinders (p0, p1, radius, a rotation, a uniform scale and a move) and rays from outside and from
/// inside: the hit distance, point, normal and uv agree with the f64 solve in world space.
#[test]
fn hits_agree_with_the_quadratic_in_f64() {
    let mut rng = Pcg32::new(29, 7);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..200 {
        let p0 = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 2.0;
        let p1 = p0 + random_unit(&mut rng) * (0.5 + 2.0 * rng.next_f32());
        let radius = 0.2 + rng.next_f32();
        let scale = 0.5 + 2.0 * rng.next_f32();
        let to_world = Transform::translate(Vec3::new(1.0, -2.0, 0.5))
            .then_after(Transform::rotate(random_unit(&mut rng), 360.0 * rng.next_f32()).unwrap())
            .then_after(Transform::scale(Vec3::splat(scale)).unwrap());
        let cyl = Cylinder::new(p0, p1, radius, to_world, false).unwrap();
        let (c0, c1) = (to_world.point(p0).as_dvec3(), to_world.point(p1).as_dvec3());
        let exact = Exact { c0, e: (c1 - c0).normalize(), len: (c1 - c0).length(), r: f64::from(radius * scale) };
        assert!((f64::from(cyl.radius()) / exact.r - 1.0).abs() < 1e-5 && (f64::from(cyl.length()) / exact.len - 1.0).abs() < 1e-5);
        let area = 2.0 * PI * exact.r * exact.len;
        assert!((f64::from(cyl.area()) / area - 1.0).abs() < 1e-5);
        let bounds = cyl.bounds();
        for _ in 0..100 {
            // Aim at a random point near the cylinder, from outside its bounds or from its axis.
            let target = (c0 + (c1 - c0) * f64::from(rng.next_f32() * 1.4 - 0.2)).as_vec3() + random_unit(&mut rng) * radius * scale * 1.3;
            let o = if rng.next_f32() < 0.7 {
                target + random_unit(&mut rng) * 10.0
            } else {
                (c0 + (c1 - c0) * f64::from(rng.next_f32())).as_vec3()
            };
            let d = (target - o).normalize();
            let (want, clear) = exact.hit(o.as_dvec3(), d.as_dvec3());
            if !clear {
                continue;
            }
            let ray = Ray::new(o, d, f32::INFINITY);
            let got = cyl.intersect(&ray);
            assert_eq!(got.is_some(), want.is_some(), "ray {o} → {d}: {got:?} vs {want:?}");
            let (Some(h), Some(t)) = (got, want) else {
                misses += 1;
                continue;
            };
            hits += 1;
            assert!((f64::from(h.t) - t).abs() < 1e-4 * t.max(1.0), "t {} vs {t}", h.t);
            let si = cyl.interaction(&ray, h.t, true);
            let p = si.p.as_dvec3();
            let z = (p - c0).dot(exact.e);
            let radial = p - c0 - exact.e * z;
            assert!((radial.length() / exact.r - 1.0).abs() < 1e-5, "off the surface");
            assert!((si.n.as_dvec3() - radial / exact.r).length() < 1e-4, "outward normal {} vs {radial}", si.n);
            assert!((f64::from(si.uv.y) - z / exact.len).abs() < 1e-4, "v {} vs {}", si.uv.y, z / exact.len);
            assert!(bounds.min.cmple(si.p + 1e-4).all() && bounds.max.cmpge(si.p - 1e-4).all());
            // The shading frame: s along the circle (∂p/∂u), t = n × s along the axis.
            let f = si.shading;
            assert!(f.s.dot(si.n).abs() < 1e-5 && f.s.as_dvec3().dot(exact.e).abs() < 1e-4 && (f.s.cross(f.t) - f.n).length() < 1e-5);
        }
    }
    assert!(hits > 5000 && misses > 2000, "{hits} hits, {misses} misses");
}

/// uv = (φ / 2π, z / L) with φ from the frame's x axis: for the default axis +z that is world x, and ∂p/∂u
/// points along increasing φ.
#[test]
fn uv_is_mitsubas() {
    let cyl = Cylinder::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 3.0), 0.5, Transform::translate(Vec3::X), false).unwrap();
    for (phi, z) in [(0.3f32, 0.25f32), (2.0, 0.9), (4.0, 0.5), (6.0, 0.1)] {
        let p = Vec3::new(1.0 + 0.5 * phi.cos(), 0.5 * phi.sin(), -1.0 + 4.0 * z);
        let o = p + Vec3::new(phi.cos(), phi.sin(), 0.0) * 2.0;
        let ray = Ray::new(o, (p - o).normalize(), f32::INFINITY);
        let si = cyl.interaction(&ray, cyl.intersect(&ray).unwrap().t, true);
        assert!((si.uv - Vec2::new(phi / (2.0 * std::f32::consts::PI), z)).length() < 1e-5, "φ {phi} z {z}: {}", si.uv);
        assert!((si.shading.s - Vec3::new(-phi.sin(), phi.cos(), 0.0)).length() < 1e-5);
    }
    // Flipped normals point inwards; the frame stays right-handed.
    let flipped = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, Transform::IDENTITY, true).unwrap();
    let ray = Ray::new(Vec3::new(3.0, 0.0, 0.5), -Vec3::X, f32::INFINITY);
    let si = flipped.interaction(&ray, flipped.intersect(&ray).unwrap().t, true);
    assert!((si.n + Vec3::X).length() < 1e-6 && (si.shading.s.cross(si.shading.t) - si.n).length() < 1e-6);
}

/// Area sampling seen from the centre of an open cylinder (radius R, length L): every point is visible,
/// so E[1 / p_ω] is the solid angle it subtends, 4π − 2 · 2π (1 − cos α) = 4π cos α with
/// cos α = (L/2) / √((L/2)² + R²); and the density `pdf_from` reports is the one sampled.
#[test]
fn area_sampling_gives_the_subtended_solid_angle() {
    let (r, len) = (0.7f32, 2.5f32);
    let to_world = Transform::rotate(Vec3::new(1.0, 2.0, 0.5).normalize(), 40.0).unwrap();
    let shape = Shape::Cylinder(Cylinder::new(Vec3::ZERO, Vec3::new(0.0, 0.0, len), r, to_world, true).unwrap());
    let centre = to_world.point(Vec3::new(0.0, 0.0, len / 2.0));
    let mut rng = Pcg32::new(3, 9);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let (ps, pdf) = shape.sample_from(centre, rng.next_f32(), rng.next_vec2()).unwrap();
        // Flipped normals face the axis.
        assert!(ps.n.dot(centre - ps.p) > 0.0);
        let back = shape.pdf_from(centre, ps.p, ps.n);
        assert!((back / pdf - 1.0).abs() < 1e-4, "{back} vs {pdf}");
        let w = 1.0 / f64::from(pdf);
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / f64::from(n);
    let sigma = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
    let half = f64::from(len / 2.0);
    let want = 4.0 * PI * half / half.hypot(f64::from(r));
    assert!((mean - want).abs() < 4.0 * sigma + 1e-4 * want, "{mean} ± {sigma} vs {want}");
}

/// Parameters that make no cylinder are errors naming the file, line and column of the parameter.
#[test]
fn bad_parameters_are_errors_with_their_place() {
    let scene = |shape: &str| {
        format!(
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>\
             <integer name=\"height\" value=\"4\"/></film></sensor>\n{shape}\n</scene>"
        )
    };
    let error = |shape: &str| {
        mitsuba_xml::load_str(&scene(shape), "bad.xml", Path::new("."), &[])
            .and_then(Scene::build)
            .map(|_| ())
            .expect_err("an error")
            .to_string()
    };
    let e = error(r#"<shape type="cylinder"><float name="radius" value="-0.5"/></shape>"#);
    assert!(e.contains("bad.xml:3:") && e.contains("`radius` of `cylinder`") && e.contains("-0.5"), "{e}");
    let e = error(r#"<shape type="cylinder"><float name="radius" value="0"/></shape>"#);
    assert!(e.contains("bad.xml:3:") && e.contains("radius"), "{e}");
    let e = error(r#"<shape type="cylinder"><point name="p0" x="1" y="2" z="3"/><point name="p1" x="1" y="2" z="3"/></shape>"#);
    assert!(e.contains("bad.xml:3:") && e.contains("`p0` and `p1` must differ"), "{e}");
    let e = error(r#"<shape type="cylinder"><transform name="to_world"><scale x="1" y="2" z="1"/></transform></shape>"#);
    assert!(e.contains("bad.xml:3:") && e.contains("circle"), "{e}");
    // Scaling along the axis only, and p0/p1 with a radius, are fine.
    let ok = scene(
        r#"<shape type="cylinder"><point name="p0" x="0" y="0" z="-1"/><point name="p1" x="1" y="1" z="1"/><float name="radius" value="0.3"/></shape>
           <shape type="cylinder"><transform name="to_world"><scale x="2" y="2" z="5"/><rotate x="1" angle="30"/></transform></shape>"#,
    );
    assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, Transform::scale(Vec3::new(2.0, 2.0, 5.0)).unwrap(), false).is_ok());
    Scene::build(mitsuba_xml::load_str(&ok, "ok.xml", Path::new("."), &[]).unwrap()).unwrap();
    assert_eq!(Cylinder::new(Vec3::ONE, Vec3::ONE, 1.0, Transform::IDENTITY, false), Err(CylinderError::NoAxis));
}
