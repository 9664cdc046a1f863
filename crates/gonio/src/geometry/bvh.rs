//! An 8-wide bounding volume hierarchy over primitive bounds.
//!
//! Built in two steps:
//! 1. a binary tree with the binned surface area heuristic (Wald 2007, "On fast Construction of SAH-based
//!    Bounding Volume Hierarchies", §3: 16 bins over the centroid extent; all three axes for small sets), whose leaf cost counts
//!    a primitive as an eighth of a test because leaves are intersected eight at a time (`tests`);
//! 2. collapsed into nodes of eight children (Dammertz et al. 2008, "Shallow Bounding Volume Hierarchies
//!    for Fast SIMD Ray Tracing of Incoherent Rays"; Wald et al. 2008, "Getting Rid of Packets"): each
//!    node pulls up the grandchildren of its largest child until it has eight.
//!
//! A node stores its children's boxes as structure-of-arrays `[f32; 8]` rows so that one ray is tested
//! against all eight boxes at once (one AVX register per row where the build targets AVX, two SSE
//! registers otherwise), choosing the near and far slab planes by the sign of the ray direction once per
//! ray (Williams et al. 2005, "An Efficient and Robust Ray–Box Intersection Algorithm").
//!
//! Leaves start at a multiple of [`LANES`] in the primitive order ([`Bvh::order`] holds [`EMPTY_SLOT`]
//! in the padding), so that callers can keep primitive data in leaf order as packets of eight.
//!
//! Traversal is geometry-agnostic: the caller passes a closure that intersects the primitives of one
//! leaf (a range of slots) with the ray, as obvhs does. Children are visited nearest first (by box entry
//! distance); farther ones are culled when a closer hit has been found by the time they are popped.
//!
//! The path tracer traces its rays eight at a time ([`Bvh::closest_rays`], [`Bvh::any_rays`]): each child
//! box is tested against the packet's rays in lanes, and the packet descends with the lanes that enter it
//! (a subtree waiting on the stack keeps each lane's entry distance, and a lane that has meanwhile found a
//! nearer hit drops out of it); a subtree that at most `ALONE_BELOW` rays reach is finished by each ray
//! alone (Benthin et al. 2012).
//! The leaves are the caller's ([`PacketLeaves`]), for rays in lanes or one by one.
//!
//! # Against a crate (2026-11)
//! `bench/bvh_compare` (a standalone crate, run by hand) set the 4-wide predecessor of this BVH against
//! obvhs 0.4 (compressed 8-wide BVH, PLOC build) on the same triangles and rays, single-threaded: on the
//! Cornell box and on spheres of 10³…10⁶ triangles it answered closest-hit queries (interaction included)
//! 1.25–2.2× and occlusion queries 1.2–2.2× faster, and built 10⁵–10⁶ triangles in about 0.8× obvhs'
//! time, with the same hits. So gonio keeps its own: its leaves test eight primitives at once and store
//! them inline in leaf order.

use super::ray::RayLanes;
use super::{Bounds3, Ray};
use crate::math::simd::{Float8, Mask8};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Primitives per packet, and the number of children of a node.
pub const LANES: usize = 8;
/// The primitive index of padding slots in [`Bvh::order`].
pub const EMPTY_SLOT: u32 = u32::MAX;
/// Number of SAH bins.
const BINS: usize = 16;
/// Leaves hold at most this many primitives (one packet).
const MAX_LEAF: usize = LANES;
/// Relative cost of a (binary) traversal step against one packet test. 2026-11: 1 measured fastest
/// among 0.25, 0.5, 1, 2 on the Cornell box (within the noise of this shared machine on a 10⁵-triangle
/// sphere).
const TRAVERSAL_COST: f32 = 1.0;
/// Sets of at most this many primitives are binned along all three axes, larger ones along the longest.
const ALL_AXES_BELOW: usize = 4096;
/// Above this depth the binary build splits at the median, which bounds the tree depth by
/// `MAX_SAH_DEPTH + log2(n)` and so the traversal stack.
const MAX_SAH_DEPTH: usize = 48;
/// Subtrees of at least this many primitives build their two halves on two threads (rayon's join): the
/// tree is the one the serial build makes, node for node (see [`Builder::append`]). Below it the halves
/// build on the thread that split them: every parallel level copies its subtrees' nodes once more, and
/// from 10⁶ primitives down to this there are already 16 tasks.
const PARALLEL_FROM: usize = 1 << 16;
/// Traversal stack entries: a node pushes at most seven, and the tree is at most
/// `MAX_SAH_DEPTH + 32` deep.
const STACK: usize = 7 * (MAX_SAH_DEPTH + 32) + 8;

/// Child reference of an empty lane.
const EMPTY_CHILD: u32 = u32::MAX;
/// A child reference with this bit set is a leaf: bits 0..28 the first packet, bits 28..31 the
/// number of packets minus one.
const LEAF_BIT: u32 = 1 << 31;
const PACKET_BITS: u32 = 28;

/// Eight children: `bounds[side][axis][lane]` is the box of child `lane`, side 0 its minimum and 1 its
/// maximum. Empty lanes have the inverted box (min +∞, max −∞), which the sign-selected slab test never
/// hits. 224 bytes, aligned to 32 so that each row is one aligned 256-bit load.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node8 {
    bounds: [[[f32; LANES]; 3]; 2],
    child: [u32; LANES],
}

/// A binary node during construction.
#[derive(Clone, Copy, Debug)]
struct BinNode {
    bounds: Bounds3,
    /// Leaf: first slot; interior: index of the second child (the first follows the node).
    offset: u32,
    /// 0 for interior nodes; else the number of primitives.
    count: u32,
}

/// The hierarchy: 8-wide nodes, and the permutation of primitive indices its leaves refer to.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node8>,
    order: Vec<u32>,
}

/// A primitive as the build sees it: its box in SIMD rows ([`BuildBox`]), its index, and whether it is
/// tested by a test of its own (see [`Bvh::build_costed`]).
#[derive(Clone, Copy, Debug)]
struct BuildPrim {
    bounds: BuildBox,
    index: u32,
    alone: bool,
}

impl BuildPrim {
    fn new(b: &Bounds3, index: u32, alone: bool) -> Self {
        BuildPrim { bounds: BuildBox { min: b.min.into(), max: b.max.into() }, index, alone }
    }

    /// The centre of its box, as [`Bounds3::centroid`] computes it.
    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        (self.bounds.min + self.bounds.max) * 0.5
    }
}

/// A box during the build: [`Bounds3`] in glam's `Vec3A` (one SSE register per corner), so that a
/// union is two instructions rather than six NaN-aware scalar ones. The primitives' bounds are finite,
/// where the two agree bit for bit. 2026-12: the build of 10⁶ triangles took 0.50 s of a 1.5 s render.
#[derive(Clone, Copy, Debug)]
struct BuildBox {
    min: Vec3A,
    max: Vec3A,
}

impl BuildBox {
    const EMPTY: BuildBox = BuildBox { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    #[inline(always)]
    fn union(self, o: BuildBox) -> Self {
        BuildBox { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline(always)]
    fn with_point(self, p: Vec3A) -> Self {
        BuildBox { min: self.min.min(p), max: self.max.max(p) }
    }

    fn to_bounds(self) -> Bounds3 {
        Bounds3 { min: self.min.into(), max: self.max.into() }
    }

    /// [`Bounds3::surface_area`] (the same operations, so the same value bit for bit) without converting
    /// the corners out of their registers: the SAH sweep takes 96 areas a node.
    #[inline(always)]
    fn surface_area(&self) -> f32 {
        // For finite corners, max − min < 0 exactly where min > max (Bounds3::is_empty); the empty box's
        // −∞ − ∞ is −∞.
        let d = self.max - self.min;
        if d.cmplt(Vec3A::ZERO).any() {
            return 0.0;
        }
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

/// The ray as the box test wants it: origin and inverse direction, splatted, and for each axis where in a
/// [`Node8`] its near and far planes' row lies: `rows[0][axis]` is the byte offset of `bounds[near][axis]`
/// (near = 1, the maximum, where the direction's sign bit is set), `rows[1][axis]` the far plane's.
/// Offsets rather than side indices: the test then addresses each row as node + offset, where from a side
/// index it computed side · 96 + axis · 32 for every row of every node (2026-12: three instructions a row,
/// twelve a node, with the index reloaded from the stack, in `perf annotate` of a closest-hit traversal;
/// without them one-ray closest hits on matpreview's path rays took 0.93× the time, median of seven
/// alternating runs, the same hits; `docs/performance.md`).
struct RayPre {
    o: [Float8; 3],
    inv_d: [Float8; 3],
    rows: [[usize; 3]; 2],
}

impl RayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let inv_d = ray.d.recip();
        let near = |axis: usize| usize::from(inv_d[axis].is_sign_negative());
        let offset = Node8::row_offset;
        RayPre {
            o: [Float8::splat(ray.o.x), Float8::splat(ray.o.y), Float8::splat(ray.o.z)],
            inv_d: [Float8::splat(inv_d.x), Float8::splat(inv_d.y), Float8::splat(inv_d.z)],
            rows: [std::array::from_fn(|a| offset(near(a), a)), std::array::from_fn(|a| offset(1 - near(a), a))],
        }
    }
}

impl Node8 {
    const EMPTY: Node8 = Node8 { bounds: [[[f32::INFINITY; LANES]; 3], [[f32::NEG_INFINITY; LANES]; 3]], child: [EMPTY_CHILD; LANES] };

    /// Which children the ray enters within (0, tmax) (bit i for child i), and their entry
    /// distances. A NaN slab (0 · ∞ for a ray in a slab's plane) is ignored, which only widens the
    /// interval: the slab's value is the first operand of `max_or_second` / `min_or_second`, which return
    /// the second where either is NaN.
    #[inline(always)]
    fn hit(&self, r: &RayPre, tmax: Float8) -> (u32, Float8) {
        let slab = |plane: usize, axis: usize| (self.row(r.rows[plane][axis]) - r.o[axis]) * r.inv_d[axis];
        let tnear = slab(0, 0).max_or_second(slab(0, 1).max_or_second(slab(0, 2).max_or_second(Float8::splat(0.0))));
        let tfar = slab(1, 0).min_or_second(slab(1, 1).min_or_second(slab(1, 2).min_or_second(tmax)));
        (tnear.le(tfar).bitmask(), tnear)
    }

    /// The byte offset of `bounds[side][axis]` in a node.
    const fn row_offset(side: usize, axis: usize) -> usize {
        std::mem::size_of::<[f32; LANES]>() * (3 * side + axis)
    }

    /// The row at byte offset `offset`, one of [`Self::row_offset`]'s.
    #[inline(always)]
    fn row(&self, offset: usize) -> Float8 {
        debug_assert!(offset % std::mem::size_of::<[f32; LANES]>() == 0 && offset <= Self::row_offset(1, 2));
        // SAFETY: `offset` is a row's byte offset within `bounds` (above), so the reference is to one whole,
        // aligned `[f32; LANES]` of this node.
        Float8::load(unsafe { &*std::ptr::addr_of!(self.bounds).cast::<u8>().add(offset).cast::<[f32; LANES]>() })
    }
}

impl Node8 {
    /// Child `c`'s box against eight rays: the lanes entering it within (0, tmax) and their entry distances,
    /// by the operations of [`Node8::hit`] in each lane.
    #[inline(always)]
    fn hit_rays(&self, c: usize, r: &PacketPre, tmax: Float8) -> (Mask8, Float8) {
        let slab = |axis: usize, near: bool| {
            let (lo, hi) = (Float8::splat(self.bounds[0][axis][c]), Float8::splat(self.bounds[1][axis][c]));
            let plane = if near { Float8::select(r.neg[axis], hi, lo) } else { Float8::select(r.neg[axis], lo, hi) };
            (plane - r.o[axis]) * r.inv_d[axis]
        };
        let tnear = slab(0, true).max_or_second(slab(1, true).max_or_second(slab(2, true).max_or_second(Float8::splat(0.0))));
        let tfar = slab(0, false).min_or_second(slab(1, false).min_or_second(slab(2, false).min_or_second(tmax)));
        (tnear.le(tfar), tnear)
    }
}

/// Decode a leaf reference into (first slot, number of slots).
#[inline(always)]
fn leaf_range(r: u32) -> (u32, u32) {
    let first_packet = r & ((1 << PACKET_BITS) - 1);
    let packets = ((r & !LEAF_BIT) >> PACKET_BITS) + 1;
    (first_packet * LANES as u32, packets * LANES as u32)
}

impl Bvh {
    /// Build over primitives with the given bounds (primitive `i` has `bounds[i]`), all of them tested
    /// eight at a time.
    #[must_use]
    pub fn build(bounds: &[Bounds3]) -> Bvh {
        Self::build_costed(bounds, &[])
    }

    /// [`Self::build`] where the primitives `i` with `alone[i]` (missing entries are false) cost the SAH a
    /// test each rather than an eighth of one: shapes whose leaf test takes each of them in turn against
    /// the packet's rays (a sphere's test, bound by its divisions and square root), which the SAH should
    /// then rather separate by nodes. 2026-12: the material spheres (five spheres) rendered about 2 %
    /// faster with their spheres so costed than counted eight to a test (`docs/performance.md`).
    #[must_use]
    pub fn build_costed(bounds: &[Bounds3], alone: &[bool]) -> Bvh {
        debug_assert!(bounds.iter().all(|b| b.min.is_finite() && b.max.is_finite()), "primitive bounds must be finite");
        let mut prims: Vec<BuildPrim> =
            bounds.par_iter().enumerate().map(|(i, b)| BuildPrim::new(b, i as u32, alone.get(i).copied().unwrap_or(false))).collect();
        if prims.is_empty() {
            return Bvh::default();
        }
        let builder = Builder::build(&mut prims, PARALLEL_FROM);
        let mut bvh = Bvh { nodes: Vec::with_capacity(builder.nodes.len() / 4 + 1), order: builder.order };
        let bin = &builder.nodes;
        if bin[0].count > 0 {
            // A single leaf: a root with one child.
            let mut root = Node8::EMPTY;
            Self::set_lane(&mut root, 0, bin[0].bounds, Self::leaf_ref(&bin[0]));
            bvh.nodes.push(root);
        } else {
            bvh.collapse(bin, 0);
        }
        bvh
    }

    fn leaf_ref(n: &BinNode) -> u32 {
        let first_packet = n.offset / LANES as u32;
        let packets = (n.count as usize).div_ceil(LANES) as u32;
        debug_assert!(first_packet < 1 << PACKET_BITS && (1..=8).contains(&packets));
        LEAF_BIT | ((packets - 1) << PACKET_BITS) | first_packet
    }

    fn set_lane(node: &mut Node8, lane: usize, b: Bounds3, child: u32) {
        for axis in 0..3 {
            node.bounds[0][axis][lane] = b.min[axis];
            node.bounds[1][axis][lane] = b.max[axis];
        }
        node.child[lane] = child;
    }

    /// Turn the interior binary node `i` (and its subtree) into 8-wide nodes; returns the node index.
    fn collapse(&mut self, bin: &[BinNode], i: usize) -> u32 {
        let children_of = |i: usize| [i + 1, bin[i].offset as usize];
        let mut kids: Vec<usize> = children_of(i).to_vec();
        // Open the interior child of largest surface area until there are eight children.
        while kids.len() < LANES {
            let Some(k) = (0..kids.len())
                .filter(|&k| bin[kids[k]].count == 0)
                .max_by(|&a, &b| bin[kids[a]].bounds.surface_area().total_cmp(&bin[kids[b]].bounds.surface_area()))
            else {
                break;
            };
            let opened = kids.swap_remove(k);
            kids.extend(children_of(opened));
        }
        let me = self.nodes.len();
        self.nodes.push(Node8::EMPTY);
        for (lane, &k) in kids.iter().enumerate() {
            let child = if bin[k].count > 0 { Self::leaf_ref(&bin[k]) } else { self.collapse(bin, k) };
            let mut node = self.nodes[me];
            Self::set_lane(&mut node, lane, bin[k].bounds, child);
            self.nodes[me] = node;
        }
        me as u32
    }

    /// The primitive stored at slot `slot`, or [`EMPTY_SLOT`] for padding (traversal closures receive
    /// slots, so that callers can keep per-primitive data in leaf order, next to each other in memory).
    #[inline]
    #[must_use]
    pub fn primitive(&self, slot: u32) -> u32 {
        self.order[slot as usize]
    }

    /// The primitives in leaf order (`order()[slot]` is the primitive at `slot`, [`EMPTY_SLOT`] for
    /// padding); its length is a multiple of [`LANES`].
    #[must_use]
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The tree as text (debugging): per node, its children as `L<first packet>x<packets>` or `N<node>`.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut out = String::new();
        for (i, n) in self.nodes.iter().enumerate() {
            out += &format!("node {i}:");
            for lane in 0..LANES {
                let c = n.child[lane];
                if c == EMPTY_CHILD {
                    continue;
                }
                if c & LEAF_BIT != 0 {
                    let (first, count) = leaf_range(c);
                    let filled = (first..first + count).filter(|&s| self.order[s as usize] != EMPTY_SLOT).count();
                    out += &format!(" L{}({filled})", first / LANES as u32);
                } else {
                    out += &format!(" N{c}");
                }
            }
            out += "\n";
        }
        out
    }

    /// Number of 8-wide nodes (for statistics).
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The closest hit: `leaf(first_slot, slot_count, tmax)` intersects the primitives of one leaf (some
    /// slots may be padding) and returns the distance of its closest hit below `tmax` with whatever the
    /// caller wants back. Returns that for the closest hit overall.
    #[inline]
    pub fn closest<H>(&self, ray: &Ray, leaf: impl FnMut(u32, u32, f32) -> Option<(f32, H)>) -> Option<H> {
        if self.nodes.is_empty() {
            return None;
        }
        closest_from(self, 0, ray, leaf)
    }

    /// Whether any primitive is hit: `leaf(first_slot, slot_count)` tests the primitives of one leaf
    /// against the ray's full extent.
    #[inline]
    pub fn any(&self, ray: &Ray, leaf: impl FnMut(u32, u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        any_from(self, 0, ray, leaf)
    }

    /// The closest hits of eight rays (the lanes of `rays` whose bit is set in `lanes`), traversed together
    /// (see [`PacketLeaves`] and the module doc): each lane's hit as its distance and slot ([`EMPTY_SLOT`]
    /// where nothing is hit below its `tmax`).
    #[inline]
    pub fn closest_rays<L: PacketLeaves>(&self, rays: &RayLanes<Float8>, lanes: u32, leaves: &L) -> Hits8 {
        let mut hits = Hits8 { t: rays.tmax, slot: [EMPTY_SLOT; PACKET] };
        if self.nodes.is_empty() || lanes == 0 {
            return hits;
        }
        let pre = PacketPre::new(rays);
        let each = PacketRays::new(rays);
        // (node, lanes, each lane's entry distance).
        let mut stack = [MaybeUninit::<(u32, u32, Float8)>::uninit(); STACK];
        let mut sp = 0usize;
        let (mut cur, mut active) = (0u32, lanes);
        'visit: loop {
            if active.count_ones() <= ALONE_BELOW {
                // Few rays left here: each finishes the subtree alone.
                let t = hits.t.to_array();
                for lane in bits(active) {
                    let ray = &each.ray(lane);
                    if let Some((tl, slot)) =
                        closest_from_t(self, cur, ray, t[lane], |first, count, tmax| leaves.closest_ray(ray, first, count, tmax))
                    {
                        hits.t = hits.t.with_lane(lane, tl);
                        hits.slot[lane] = slot;
                    }
                }
            } else if cur & LEAF_BIT != 0 {
                let (first, count) = leaf_range(cur);
                leaves.closest_rays(rays, &each, first, count, active, &mut hits);
            } else {
                let node = &self.nodes[cur as usize];
                // The children the rays enter, nearest (by the smallest entry distance of their rays) first.
                let mut kids = [(0u32, 0u32, 0.0f32, Float8::splat(0.0)); LANES];
                let mut n = 0;
                for c in 0..LANES {
                    let child = node.child[c];
                    if child == EMPTY_CHILD {
                        break;
                    }
                    let (hit, tnear) = node.hit_rays(c, &pre, hits.t);
                    let m = hit.bitmask() & active;
                    if m == 0 {
                        continue;
                    }
                    let dist = Float8::select(Mask8::from_bitmask(m), tnear, Float8::splat(f32::INFINITY)).min_lane();
                    let mut j = n;
                    while j > 0 && kids[j - 1].2 > dist {
                        kids[j] = kids[j - 1];
                        j -= 1;
                    }
                    kids[j] = (child, m, dist, tnear);
                    n += 1;
                }
                if n > 0 {
                    for &(child, m, _, tnear) in kids[1..n].iter().rev() {
                        stack[sp].write((child, m, tnear));
                        sp += 1;
                    }
                    (cur, active) = (kids[0].0, kids[0].1);
                    continue 'visit;
                }
            }
            // Pop the next subtree, with the lanes that can still find a closer hit in it: those whose hit so
            // far is not nearer than their own entry into its box. (2026-12: by each lane's entry rather than
            // the packet's nearest, the Cornell box and the material spheres rendered 0.97–0.98× the time in
            // five of seven alternations, 1.03–1.05× in two; same images. `docs/performance.md`.)
            loop {
                if sp == 0 {
                    return hits;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the pushes above.
                let (node, m, tnear) = unsafe { stack[sp].assume_init() };
                let m = m & hits.t.ge(tnear).bitmask();
                if m != 0 {
                    (cur, active) = (node, m);
                    continue 'visit;
                }
            }
        }
    }

    /// Which of eight rays (the lanes of `rays` set in `lanes`) are blocked before their `tmax`, traversed
    /// together; a bit mask.
    #[inline]
    pub fn any_rays<L: PacketLeaves>(&self, rays: &RayLanes<Float8>, lanes: u32, leaves: &L) -> u32 {
        let mut blocked = 0u32;
        if self.nodes.is_empty() || lanes == 0 {
            return blocked;
        }
        let pre = PacketPre::new(rays);
        let each = PacketRays::new(rays);
        let mut stack = [MaybeUninit::<(u32, u32)>::uninit(); STACK];
        let mut sp = 0usize;
        let (mut cur, mut active) = (0u32, lanes);
        loop {
            if active.count_ones() <= ALONE_BELOW {
                for lane in bits(active) {
                    let ray = &each.ray(lane);
                    if any_from(self, cur, ray, |first, count| leaves.any_ray(ray, first, count)) {
                        blocked |= 1 << lane;
                    }
                }
            } else if cur & LEAF_BIT != 0 {
                let (first, count) = leaf_range(cur);
                blocked |= leaves.any_rays(rays, &each, first, count, active);
                if blocked == lanes {
                    return blocked;
                }
            } else {
                let node = &self.nodes[cur as usize];
                for c in 0..LANES {
                    let child = node.child[c];
                    if child == EMPTY_CHILD {
                        break;
                    }
                    let m = node.hit_rays(c, &pre, rays.tmax).0.bitmask() & active;
                    if m != 0 {
                        stack[sp].write((child, m));
                        sp += 1;
                    }
                }
            }
            loop {
                if sp == 0 {
                    return blocked;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the pushes above.
                let (node, m) = unsafe { stack[sp].assume_init() };
                let m = m & !blocked;
                if m != 0 {
                    (cur, active) = (node, m);
                    break;
                }
            }
        }
    }
}

/// Rays per packet.
pub const PACKET: usize = 8;

/// Below this many rays a packet's subtree is traversed by each ray alone (Benthin et al. 2012, "Combining
/// Single and Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC Architecture"): the packet
/// tests cost the same for one ray as for eight. 2026-12: on a path tracer's packets (gonio-bench/benches/bvh.rs,
/// `packets`) 1 was 2–3 % faster than 2 for closest hits and 4–5 % for shadow rays on the Cornell box, and
/// no slower on the material spheres; 3 was slower on both; all eight alone (8) half again as slow.
const ALONE_BELOW: u32 = 1;

/// The closest hits of a packet: per lane the distance and the slot hit ([`EMPTY_SLOT`] for none).
#[derive(Clone, Copy, Debug)]
pub struct Hits8 {
    pub t: Float8,
    pub slot: [u32; PACKET],
}

/// The primitives' side of packet traversal: the tests of one leaf (slots `first..first + count`, some of
/// them padding) for several rays at once, and for one ray (when few rays remain in a subtree). The
/// packet's rays come both as lanes and as rows to take one from (`each`, with the packet's `tmax`).
pub trait PacketLeaves {
    /// Update `hits` (distance and slot per lane) with the closer hits of the rays in `lanes`.
    fn closest_rays(&self, rays: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32, hits: &mut Hits8);
    /// The closest hit of one ray below `tmax`: its distance and slot.
    fn closest_ray(&self, ray: &Ray, first: u32, count: u32, tmax: f32) -> Option<(f32, u32)>;
    /// The rays in `lanes` that something in the leaf blocks before their `tmax` (a bit mask).
    fn any_rays(&self, rays: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32) -> u32;
    /// Whether something in the leaf blocks one ray.
    fn any_ray(&self, ray: &Ray, first: u32, count: u32) -> bool;
}

/// The set lanes of a mask of [`LANES`] lanes (no bit above them), lowest first. Each lane is known to
/// the compiler to be below [`LANES`], so that indexing a lane's array needs no bounds check (2026-12:
/// 1–2 % fewer instructions per sample).
#[inline(always)]
pub fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    debug_assert!(m >> LANES == 0, "{m:#x} has bits above lane {LANES}");
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let lane = m.trailing_zeros() as usize & (LANES - 1);
            m &= m - 1;
            lane
        })
    })
}

/// The set lanes of `m` (as in [`bits`]) in groups, lowest lane first: that lane and the mask of its
/// group (`group(lane)`, kept to the lanes not yet grouped; the lane itself always belongs), until every
/// lane is in one.
#[inline(always)]
pub fn groups(mut m: u32, mut group: impl FnMut(usize) -> u32) -> impl Iterator<Item = (usize, u32)> {
    debug_assert!(m >> LANES == 0, "{m:#x} has bits above lane {LANES}");
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let lane = m.trailing_zeros() as usize & (LANES - 1);
            let same = (group(lane) & m) | 1 << lane;
            m &= !same;
            (lane, same)
        })
    })
}

/// The rays of a packet as rows, from which one ray is read when it is needed alone (2026-12: the eight
/// rays taken apart into `Ray`s at every traversal, most of which never needed one, were 1.6–1.8 % of a
/// render's time).
pub struct PacketRays {
    o: [[f32; PACKET]; 3],
    d: [[f32; PACKET]; 3],
    tmax: [f32; PACKET],
}

impl PacketRays {
    #[inline(always)]
    #[must_use]
    pub fn new(r: &RayLanes<Float8>) -> Self {
        PacketRays {
            o: [r.o.x.to_array(), r.o.y.to_array(), r.o.z.to_array()],
            d: [r.d.x.to_array(), r.d.y.to_array(), r.d.z.to_array()],
            tmax: r.tmax.to_array(),
        }
    }

    /// The ray of lane `lane`.
    #[inline(always)]
    #[must_use]
    pub fn ray(&self, lane: usize) -> Ray {
        let row = |r: &[[f32; PACKET]; 3]| Vec3::new(r[0][lane], r[1][lane], r[2][lane]);
        Ray::new(row(&self.o), row(&self.d), self.tmax[lane])
    }
}

/// Eight rays as the packet box test wants them: origins, inverse directions, and per axis the lanes
/// whose near slab plane is the box's maximum.
struct PacketPre {
    o: [Float8; 3],
    inv_d: [Float8; 3],
    neg: [Mask8; 3],
}

impl PacketPre {
    #[inline(always)]
    fn new(r: &RayLanes<Float8>) -> Self {
        let one = Float8::splat(1.0);
        let inv_d = [one / r.d.x, one / r.d.y, one / r.d.z];
        // Sign bit set (as `is_sign_negative` of the single-ray test): −0 counts as negative.
        let neg = |v: Float8| Float8::splat(1.0).xor_sign(v).lt(Float8::splat(0.0));
        PacketPre { o: [r.o.x, r.o.y, r.o.z], inv_d, neg: [neg(inv_d[0]), neg(inv_d[1]), neg(inv_d[2])] }
    }
}

/// [`Bvh::closest`]. Children are visited nearest first; the others wait on a stack with their entry
/// distance and are dropped when popped behind the closest hit found by then. (2026-11: a copy of the
/// traversal per ray octant, with the near planes known at compile time, took fewer instructions but more
/// time: eight copies of the leaf tests crowd the instruction cache.)
#[inline(always)]
fn closest_from<H>(bvh: &Bvh, start: u32, ray: &Ray, leaf: impl FnMut(u32, u32, f32) -> Option<(f32, H)>) -> Option<H> {
    closest_from_t(bvh, start, ray, ray.tmax, leaf).map(|(_, h)| h)
}

/// [`closest_from`] below `tmax` rather than the ray's own, returning the distance of the hit too.
#[inline(always)]
fn closest_from_t<H>(
    bvh: &Bvh,
    start: u32,
    ray: &Ray,
    tmax: f32,
    mut leaf: impl FnMut(u32, u32, f32) -> Option<(f32, H)>,
) -> Option<(f32, H)> {
    let mut best = None;
    let pre = RayPre::new(ray);
    let mut tmax = tmax;
    let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); STACK];
    let mut sp = 0usize;
    let mut cur = start;
    'visit: loop {
        if cur & LEAF_BIT != 0 {
            let (first, count) = leaf_range(cur);
            if let Some((t, h)) = leaf(first, count, tmax) {
                tmax = t;
                best = Some((t, h));
            }
        } else {
            let node = &bvh.nodes[cur as usize];
            let (mask, tnear) = node.hit(&pre, Float8::splat(tmax));
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = node.child[first];
                    continue 'visit;
                }
                let tnear = tnear.to_array();
                let second = rest.trailing_zeros() as usize;
                if rest & (rest - 1) == 0 {
                    // Two children (the common case after one): the nearer now, the other on the stack.
                    let (a, b) = ((node.child[first], tnear[first]), (node.child[second], tnear[second]));
                    let (near, far) = if b.1 < a.1 { (b, a) } else { (a, b) };
                    stack[sp].write(far);
                    sp += 1;
                    cur = near.0;
                    continue 'visit;
                }
                // Sort the hit children by entry distance (at most eight: insertion sort, stable).
                let mut hits = [(0u32, 0.0f32); LANES];
                let mut n = 0;
                for lane in bits(mask) {
                    let entry = (node.child[lane], tnear[lane]);
                    let mut j = n;
                    while j > 0 && hits[j - 1].1 > entry.1 {
                        hits[j] = hits[j - 1];
                        j -= 1;
                    }
                    hits[j] = entry;
                    n += 1;
                }
                // Push the farther ones, farthest first; go on with the nearest.
                for &h in hits[1..n].iter().rev() {
                    stack[sp].write(h);
                    sp += 1;
                }
                cur = hits[0].0;
                continue 'visit;
            }
        }
        // Pop the next child that can still hold a hit closer than tmax.
        loop {
            if sp == 0 {
                return best;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            let (r, tnear) = unsafe { stack[sp].assume_init() };
            if tnear <= tmax {
                cur = r;
                continue 'visit;
            }
        }
    }
}

/// [`Bvh::any`].
#[inline(always)]
fn any_from(bvh: &Bvh, start: u32, ray: &Ray, mut leaf: impl FnMut(u32, u32) -> bool) -> bool {
    let pre = RayPre::new(ray);
    let tmax = Float8::splat(ray.tmax);
    let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
    let mut sp = 0usize;
    let mut cur = start;
    loop {
        if cur & LEAF_BIT != 0 {
            let (first, count) = leaf_range(cur);
            if leaf(first, count) {
                return true;
            }
        } else {
            let node = &bvh.nodes[cur as usize];
            let (mask, _) = node.hit(&pre, tmax);
            for lane in bits(mask) {
                stack[sp].write(node.child[lane]);
                sp += 1;
            }
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above.
        cur = unsafe { stack[sp].assume_init() };
    }
}

/// The binary SAH build.
struct Builder {
    nodes: Vec<BinNode>,
    order: Vec<u32>,
    /// Subtrees of at least this many primitives build their halves in parallel ([`PARALLEL_FROM`]).
    parallel_from: usize,
}

/// SAH cost of `n` primitives of which `alone` are tested each by itself (a test each), the others an
/// eighth of a test each. Not a whole test per started packet of eight: the path tracer's packets test a
/// leaf triangle by triangle against their rays, so a leaf of two triangles costs a quarter of one of
/// eight. 2026-12: the Cornell box's walls then get leaves of their own rather than sharing packets
/// whose boxes span the room, and it rendered with 6.5 % fewer instructions (0.97 × the time); the
/// material spheres' tree stayed the same, and tessellated spheres of 10⁴ and 10⁶ triangles took 1.00 ×
/// and 1.01 × the instructions.
#[inline]
fn tests(n: usize, alone: usize) -> f32 {
    (n - alone) as f32 / LANES as f32 + alone as f32
}

/// The two sides of a split: where the second begins in the primitives, and each side's box and the box
/// of its centroids.
struct Split {
    mid: usize,
    sides: [(BuildBox, BuildBox); 2],
}

impl Builder {
    /// The binary tree over `prims` (reordered), its slots padded to a packet boundary.
    fn build(prims: &mut [BuildPrim], parallel_from: usize) -> Builder {
        let (bounds, cbounds) = boxes_of(prims);
        let mut builder = Builder::subtree(prims, bounds, cbounds, 0, parallel_from);
        while builder.order.len() % LANES != 0 {
            builder.order.push(EMPTY_SLOT);
        }
        builder
    }

    /// The tree of `prims` (within `bounds`, their centroids within `cbounds`), at `depth`, in a builder of
    /// its own.
    fn subtree(prims: &mut [BuildPrim], bounds: BuildBox, cbounds: BuildBox, depth: usize, parallel_from: usize) -> Builder {
        let mut sub = Builder { nodes: Vec::with_capacity(2 * prims.len()), order: Vec::with_capacity(prims.len() + 8), parallel_from };
        sub.build_node(prims, bounds, cbounds, depth);
        sub
    }

    fn push_leaf(&mut self, bounds: BuildBox, prims: &[BuildPrim]) {
        // Leaves start on a packet boundary.
        while self.order.len() % LANES != 0 {
            self.order.push(EMPTY_SLOT);
        }
        let offset = self.order.len() as u32;
        self.order.extend(prims.iter().map(|p| p.index));
        self.nodes.push(BinNode { bounds: bounds.to_bounds(), offset, count: prims.len() as u32 });
    }

    /// The node of `prims`, whose boxes `bounds` bounds and whose centroids `cbounds` bounds: each split
    /// hands its sides their boxes (from its bins and its partition pass), so no node folds its
    /// primitives again.
    fn build_node(&mut self, prims: &mut [BuildPrim], bounds: BuildBox, cbounds: BuildBox, depth: usize) {
        let n = prims.len();
        if n == 1 {
            self.push_leaf(bounds, prims);
            return;
        }
        let axis = cbounds.to_bounds().longest_axis();
        let (lo, hi) = (cbounds.min[axis], cbounds.max[axis]);
        // hi > lo on the longest axis: some axis separates the centroids.
        let split = if hi > lo && depth < MAX_SAH_DEPTH {
            match sah_split(prims, &bounds, &cbounds) {
                Some(split) => split,
                None if n <= MAX_LEAF => {
                    self.push_leaf(bounds, prims);
                    return;
                }
                None => median_split(prims, axis),
            }
        } else if n <= MAX_LEAF {
            // All centroids coincide (nothing separates them), or the tree is deep already.
            self.push_leaf(bounds, prims);
            return;
        } else {
            median_split(prims, axis)
        };
        let me = self.nodes.len();
        self.nodes.push(BinNode { bounds: bounds.to_bounds(), offset: 0, count: 0 });
        let (left, right) = prims.split_at_mut(split.mid);
        let [(lb, lc), (rb, rc)] = split.sides;
        if n >= self.parallel_from {
            let from = self.parallel_from;
            let (l, r) =
                rayon::join(|| Builder::subtree(left, lb, lc, depth + 1, from), || Builder::subtree(right, rb, rc, depth + 1, from));
            self.append(l);
            self.nodes[me].offset = self.nodes.len() as u32;
            self.append(r);
        } else {
            self.build_node(left, lb, lc, depth + 1);
            self.nodes[me].offset = self.nodes.len() as u32;
            self.build_node(right, rb, rc, depth + 1);
        }
    }

    /// Append a subtree built by a builder of its own, as if this builder had built it next: its nodes
    /// move by the nodes here, its slots by the slots here after padding them to a packet boundary (which
    /// its first leaf would have done; the subtree's own slots start at 0, a boundary), so the result is
    /// the serial build's.
    fn append(&mut self, sub: Builder) {
        while self.order.len() % LANES != 0 {
            self.order.push(EMPTY_SLOT);
        }
        let (node_base, slot_base) = (self.nodes.len() as u32, self.order.len() as u32);
        self.nodes.extend(sub.nodes.into_iter().map(|mut n| {
            n.offset += if n.count > 0 { slot_base } else { node_base };
            n
        }));
        self.order.extend(sub.order);
    }
}

/// The box of `prims` and the box of their centroids.
fn boxes_of(prims: &[BuildPrim]) -> (BuildBox, BuildBox) {
    prims.iter().fold((BuildBox::EMPTY, BuildBox::EMPTY), |(b, c), p| (b.union(p.bounds), c.with_point(p.centroid())))
}

/// The bins of one axis: each bin's primitives, how many of them are tested alone, and their box.
#[derive(Clone, Copy)]
struct Bins {
    counts: [usize; BINS],
    alone: [usize; BINS],
    bounds: [BuildBox; BINS],
}

/// Partition by the cheapest bin boundary over all three axes (`cbounds` bounds the centroids);
/// `None` when a leaf is cheaper (and small enough).
fn sah_split(prims: &mut [BuildPrim], bounds: &BuildBox, cbounds: &BuildBox) -> Option<Split> {
    let longest = cbounds.to_bounds().longest_axis();
    // All three axes for small sets, where the better split is cheap to find; the longest one for large
    // sets, where binning three times would triple the build time (2026-11: 10⁶ triangles). Axes along
    // which the centroids do not spread are not binned.
    let candidates = if prims.len() <= ALL_AXES_BELOW { 0..3 } else { longest..longest + 1 };
    let mut axes = [0usize; 3];
    let mut axis_count = 0;
    for axis in candidates {
        if cbounds.max[axis] > cbounds.min[axis] {
            (axes[axis_count], axis_count) = (axis, axis_count + 1);
        }
    }
    let axes = &axes[..axis_count];
    let (lo, scale) = (cbounds.min, Vec3A::splat(BINS as f32) / (cbounds.max - cbounds.min));
    // A centroid's bin along each axis, all three in one vector: ⌊(c − lo) · scale⌋ clamped to the bins
    // (a NaN, from an axis not binned or a scale that overflowed, to bin 0: `max` returns its second
    // operand where either is NaN), so the conversion to integers needs no saturation.
    let last = Vec3A::splat((BINS - 1) as f32);
    let bins_of = |c: Vec3A| ((c - lo) * scale).max(Vec3A::ZERO).min(last).as_ivec3().to_array().map(|b| b as usize);
    // One pass over the primitives bins them along every axis binned.
    let mut bins = [Bins { counts: [0; BINS], alone: [0; BINS], bounds: [BuildBox::EMPTY; BINS] }; 3];
    for p in prims.iter() {
        let b3 = bins_of(p.centroid());
        for &axis in axes {
            let b = b3[axis];
            let bins = &mut bins[axis];
            bins.counts[b] += 1;
            bins.alone[b] += usize::from(p.alone);
            bins.bounds[b] = bins.bounds[b].union(p.bounds);
        }
    }
    // (cost, axis, bin boundary)
    let mut best = (f32::INFINITY, 0, 0);
    // The primitives tested alone, counted by the binning (every binned axis sees them all).
    let mut all_alone = 0;
    for &axis in axes {
        let Bins { counts, alone, bounds: bin_bounds } = &bins[axis];
        all_alone = alone.iter().sum();
        // Sweep from the right to get the area and count right of each boundary, then from the left.
        let mut right_area = [0.0f32; BINS];
        let (mut right_count, mut right_alone) = ([0usize; BINS], [0usize; BINS]);
        let (mut acc, mut cnt, mut one) = (BuildBox::EMPTY, 0, 0);
        for i in (1..BINS).rev() {
            acc = acc.union(bin_bounds[i]);
            (cnt, one) = (cnt + counts[i], one + alone[i]);
            right_area[i] = acc.surface_area();
            (right_count[i], right_alone[i]) = (cnt, one);
        }
        let (mut acc, mut cnt, mut one) = (BuildBox::EMPTY, 0, 0);
        for i in 1..BINS {
            acc = acc.union(bin_bounds[i - 1]);
            (cnt, one) = (cnt + counts[i - 1], one + alone[i - 1]);
            let cost = tests(cnt, one) * acc.surface_area() + tests(right_count[i], right_alone[i]) * right_area[i];
            if cnt > 0 && right_count[i] > 0 && cost < best.0 {
                best = (cost, axis, i);
            }
        }
    }
    let (cost, axis, boundary) = best;
    if boundary == 0 {
        return None;
    }
    let leaf_cost = tests(prims.len(), all_alone);
    let split_cost = TRAVERSAL_COST + cost / bounds.surface_area().max(f32::MIN_POSITIVE);
    if split_cost >= leaf_cost && prims.len() <= MAX_LEAF {
        return None;
    }
    // The sides' boxes are their bins'; their centroids' boxes come from the partition.
    let side_box = |range: std::ops::Range<usize>| bins[axis].bounds[range].iter().fold(BuildBox::EMPTY, |a, &b| a.union(b));
    let (left_box, right_box) = (side_box(0..boundary), side_box(boundary..BINS));
    let (mut left_c, mut right_c) = (BuildBox::EMPTY, BuildBox::EMPTY);
    let (lo, scale) = (lo[axis], scale[axis]);
    let along = |c: Vec3A| match axis {
        0 => c.x,
        1 => c.y,
        _ => c.z,
    };
    // Bin ⌊x⌋ (clamped to the bins, NaN to bin 0) is below the boundary b ∈ 1..BINS exactly where x < b
    // or x is NaN.
    let left_of = |c: Vec3A| {
        let x = (along(c) - lo) * scale;
        x < boundary as f32 || x.is_nan()
    };
    // Hoare's partition from both ends: only the primitives on the wrong side move (the SAH's sides of
    // spatially ordered triangles mostly are in place), where a one-ended pass moved every left one.
    // The centroid boxes take every primitive once it is known in place.
    let (mut i, mut j) = (0, prims.len());
    loop {
        while i < j {
            let c = prims[i].centroid();
            if !left_of(c) {
                break;
            }
            left_c = left_c.with_point(c);
            i += 1;
        }
        while i < j {
            let c = prims[j - 1].centroid();
            if left_of(c) {
                break;
            }
            right_c = right_c.with_point(c);
            j -= 1;
        }
        if i == j {
            break;
        }
        // prims[i] belongs right and prims[j − 1] left.
        prims.swap(i, j - 1);
    }
    Some(Split { mid: i, sides: [(left_box, left_c), (right_box, right_c)] })
}

/// Split at the median centroid along `axis` (when the SAH cannot separate a large set).
fn median_split(prims: &mut [BuildPrim], axis: usize) -> Split {
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
    let (left, right) = prims.split_at(mid);
    Split { mid, sides: [boxes_of(left), boxes_of(right)] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    fn random_boxes(rng: &mut Pcg32, n: usize) -> Vec<Bounds3> {
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
                Bounds3 { min: c, max: c + Vec3::splat(0.05 + 0.2 * rng.next_f32()) }
            })
            .collect()
    }

    /// The parallel build makes the serial build's tree, node for node and slot for slot.
    #[test]
    fn parallel_build_is_the_serial_build() {
        let mut rng = Pcg32::new(5, 11);
        for n in [9, 100, 5000, 40_000] {
            let boxes = random_boxes(&mut rng, n);
            let prims = |alone: bool| -> Vec<BuildPrim> {
                boxes.iter().enumerate().map(|(i, b)| BuildPrim::new(b, i as u32, alone && i % 3 == 0)).collect()
            };
            for alone in [false, true] {
                let serial = Builder::build(&mut prims(alone), usize::MAX);
                // Down to subtrees of two primitives in parallel: every join and append exercised.
                let parallel = Builder::build(&mut prims(alone), 2);
                assert_eq!(serial.order, parallel.order, "n = {n}");
                assert_eq!(serial.nodes.len(), parallel.nodes.len(), "n = {n}");
                for (a, b) in serial.nodes.iter().zip(&parallel.nodes) {
                    assert!(a.offset == b.offset && a.count == b.count && a.bounds == b.bounds, "n = {n}");
                }
            }
        }
    }

    /// Every node's box is exactly the box of its primitives, although no node folds them: a split hands
    /// its sides the boxes of its bins and of its partition (and a median split folds them).
    #[test]
    fn handed_down_boxes_are_exact() {
        let mut rng = Pcg32::new(7, 3);
        for (n, spread) in [(2, true), (300, true), (5000, true), (20_000, false)] {
            // Without spread, many centroids coincide: median splits.
            let boxes: Vec<Bounds3> = random_boxes(&mut rng, n)
                .into_iter()
                .enumerate()
                .map(|(i, b)| {
                    if spread {
                        b
                    } else {
                        Bounds3 { min: Vec3::splat((i % 40) as f32), max: Vec3::splat((i % 40) as f32) + b.diagonal() }
                    }
                })
                .collect();
            let mut prims: Vec<BuildPrim> = boxes.iter().enumerate().map(|(i, b)| BuildPrim::new(b, i as u32, i % 4 == 0)).collect();
            let tree = Builder::build(&mut prims, 64);
            // The box of binary node `i`'s subtree, from the primitives of its leaves.
            fn check(tree: &Builder, boxes: &[Bounds3], i: usize) -> Bounds3 {
                let node = &tree.nodes[i];
                let folded = if node.count > 0 {
                    let slots = &tree.order[node.offset as usize..(node.offset + node.count) as usize];
                    slots.iter().fold(Bounds3::EMPTY, |b, &p| b.union(boxes[p as usize]))
                } else {
                    check(tree, boxes, i + 1).union(check(tree, boxes, node.offset as usize))
                };
                assert_eq!(node.bounds, folded, "node {i}");
                folded
            }
            check(&tree, &boxes, 0);
        }
    }

    /// Random small boxes; the BVH must find exactly what brute force finds, built with every primitive
    /// packed, and with random ones costed alone.
    #[test]
    fn closest_and_any_match_brute_force() {
        let mut rng = Pcg32::new(3, 7);
        for (n, costed) in [1, 3, 5, 2000, 5000].into_iter().flat_map(|n| [(n, false), (n, true)]) {
            let boxes = random_boxes(&mut rng, n);
            let alone: Vec<bool> = (0..if costed { n } else { 0 }).map(|_| rng.next_f32() < 0.5).collect();
            let bvh = Bvh::build_costed(&boxes, &alone);
            assert_eq!(bvh.order().len() % LANES, 0);
            let mut seen: Vec<u32> = bvh.order().iter().copied().filter(|&i| i != EMPTY_SLOT).collect();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>(), "every primitive in exactly one leaf");
            for _ in 0..500 {
                let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - Vec3::ONE;
                let d = crate::sampling::warp::sample_uniform_sphere(rng.next_vec2());
                let ray = Ray::new(o, d, 20.0);
                let inv = d.recip();
                let test = |i: u32, tmax: f32| boxes[i as usize].hit(o, inv, tmax).filter(|&t| t > 0.0);
                let brute = (0..n as u32).filter_map(|i| test(i, 20.0).map(|t| (t, i))).min_by(|a, b| a.0.total_cmp(&b.0));
                let found = bvh.closest(&ray, |first, count, tmax| {
                    (first..first + count)
                        .map(|s| bvh.primitive(s))
                        .filter(|&i| i != EMPTY_SLOT)
                        .filter_map(|i| test(i, tmax).map(|t| (t, i)))
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                });
                assert_eq!(brute.map(|b| b.1), found);
                let any = bvh.any(&ray, |first, count| {
                    (first..first + count).map(|s| bvh.primitive(s)).any(|i| i != EMPTY_SLOT && test(i, 20.0).is_some())
                });
                assert_eq!(brute.is_some(), any);
            }
        }
    }

    /// Boxes as a packet traversal's leaves: each ray tested against each box, lane by lane.
    struct BoxLeaves<'a>(&'a Bvh, &'a [Bounds3]);

    impl BoxLeaves<'_> {
        /// The nearest box of slots `first..first + count` that `ray` enters before `tmax` (the first slot
        /// among equals), and where.
        fn nearest(&self, ray: &Ray, first: u32, count: u32, tmax: f32) -> Option<(f32, u32)> {
            let mut best: Option<(f32, u32)> = None;
            for slot in first..first + count {
                let i = self.0.primitive(slot);
                if i == EMPTY_SLOT {
                    continue;
                }
                let limit = best.map_or(tmax, |b| b.0);
                if let Some(t) = self.1[i as usize].hit(ray.o, ray.d.recip(), limit).filter(|&t| t > 0.0 && t < limit) {
                    best = Some((t, slot));
                }
            }
            best
        }
    }

    impl PacketLeaves for BoxLeaves<'_> {
        fn closest_rays(&self, _: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32, hits: &mut Hits8) {
            for lane in bits(lanes) {
                if let Some((t, slot)) = self.nearest(&each.ray(lane), first, count, hits.t.lane(lane)) {
                    hits.t = hits.t.with_lane(lane, t);
                    hits.slot[lane] = slot;
                }
            }
        }
        fn closest_ray(&self, ray: &Ray, first: u32, count: u32, tmax: f32) -> Option<(f32, u32)> {
            self.nearest(ray, first, count, tmax)
        }
        fn any_rays(&self, _: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32) -> u32 {
            bits(lanes).filter(|&lane| self.any_ray(&each.ray(lane), first, count)).fold(0, |m, lane| m | 1 << lane)
        }
        fn any_ray(&self, ray: &Ray, first: u32, count: u32) -> bool {
            self.nearest(ray, first, count, ray.tmax).is_some()
        }
    }

    /// Packets of eight incoherent rays (random origins, directions and lengths, some lanes off, as a path
    /// tracer's bounces) find each ray's nearest box and its blocked rays as brute force does: the packet
    /// traversal's culling of subtrees per lane never drops a lane's nearest hit.
    #[test]
    fn incoherent_packets_match_brute_force() {
        let mut rng = Pcg32::new(5, 11);
        let boxes = random_boxes(&mut rng, 3000);
        let bvh = Bvh::build(&boxes);
        let (mut hit, mut missed) = (0, 0);
        for _ in 0..400 {
            let rays: [Ray; PACKET] = std::array::from_fn(|_| {
                let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
                Ray::new(o, crate::sampling::warp::sample_uniform_sphere(rng.next_vec2()), 0.5 + 8.0 * rng.next_f32())
            });
            let lanes = RayLanes::from_rays(&rays);
            let live = (rng.next_u32() & 0xff) | 0b1110_0001;
            let leaves = BoxLeaves(&bvh, &boxes);
            let hits = bvh.closest_rays(&lanes, live, &leaves);
            let blocked = bvh.any_rays(&lanes, live, &leaves);
            for (lane, ray) in rays.iter().enumerate() {
                let on = live & 1 << lane != 0;
                let brute = on.then(|| leaves.nearest(ray, 0, bvh.order().len() as u32, ray.tmax)).flatten();
                let got = (hits.slot[lane] != EMPTY_SLOT).then(|| (hits.t.lane(lane), hits.slot[lane]));
                assert_eq!(got.map(|g| bvh.primitive(g.1)), brute.map(|b| bvh.primitive(b.1)), "lane {lane}");
                assert_eq!(got.map(|g| g.0), brute.map(|b| b.0), "lane {lane}");
                assert_eq!(blocked & 1 << lane != 0, brute.is_some(), "lane {lane}");
                if on {
                    (hit, missed) = if brute.is_some() { (hit + 1, missed) } else { (hit, missed + 1) };
                }
            }
        }
        assert!(hit > 500 && missed > 200, "{hit} rays hit a box, {missed} missed all");
    }

    /// `groups` puts every set lane in exactly one group, lowest lane first, within the lanes left.
    #[test]
    fn lanes_fall_into_groups() {
        let key = [3, 1, 3, 7, 1, 3, 9, 9];
        let same = |l: usize| (0..8).filter(|&k| key[k] == key[l]).fold(0, |m, k| m | 1 << k);
        let got: Vec<(usize, u32)> = groups(0b1111_0111, same).collect();
        assert_eq!(got, [(0, 0b0010_0101), (1, 0b0001_0010), (6, 0b1100_0000)]);
        // A group that leaves its own lane out still holds it.
        assert_eq!(groups(0b101, |_| 0).collect::<Vec<_>>(), [(0, 0b001), (2, 0b100)]);
    }

    /// Eight well separated boxes: as packed primitives one leaf holds them all (a single test costs less
    /// than a node), as primitives tested alone each gets a leaf of its own.
    #[test]
    fn primitives_tested_alone_get_their_own_leaves() {
        let boxes: Vec<Bounds3> = (0..8)
            .map(|i| {
                let c = Vec3::new(3.0 * i as f32, 0.0, 0.0);
                Bounds3 { min: c, max: c + Vec3::ONE }
            })
            .collect();
        let leaves = |bvh: &Bvh| {
            let mut refs: Vec<u32> = bvh.nodes.iter().flat_map(|n| n.child).filter(|&c| c != EMPTY_CHILD && c & LEAF_BIT != 0).collect();
            refs.sort_unstable();
            refs.dedup();
            refs.len()
        };
        assert_eq!(leaves(&Bvh::build(&boxes)), 1);
        assert_eq!(leaves(&Bvh::build_costed(&boxes, &[true; 8])), 8);
    }

    /// Rays along the axes (infinite inverse direction components) and flat boxes (zero extent on one
    /// axis, like the walls of a room) are still found.
    #[test]
    fn axis_aligned_rays_hit_flat_boxes() {
        let boxes: Vec<Bounds3> = (0..9)
            .map(|i| {
                let z = i as f32;
                Bounds3 { min: Vec3::new(-1.0, -1.0, z), max: Vec3::new(1.0, 1.0, z) }
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        for (o, d, want) in [
            (Vec3::new(0.0, 0.0, -1.0), Vec3::Z, Some(0)),
            (Vec3::new(0.5, -0.5, 9.5), -Vec3::Z, Some(8)),
            (Vec3::new(0.0, 0.0, 3.5), Vec3::X, None),
            (Vec3::new(-5.0, 0.0, 4.0), Vec3::X, Some(4)),
        ] {
            let ray = Ray::new(o, d, f32::INFINITY);
            let inv = d.recip();
            let found = bvh.closest(&ray, |first, count, tmax| {
                (first..first + count)
                    .map(|s| bvh.primitive(s))
                    .filter(|&i| i != EMPTY_SLOT)
                    .filter_map(|i| boxes[i as usize].hit(o, inv, tmax).map(|t| (t, i)))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
            });
            assert_eq!(found, want, "{o} {d}");
        }
    }
}
