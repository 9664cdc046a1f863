"""Reference hits on Mitsuba 3's `sdfgrid` for gonio's test `sdf_grid_matches_mitsuba` (tests/sdf_grid.rs).

Renders nothing: traces rays against the torus grid of ../shared/data/mitsuba-scenes (mitsuba-data's
docs/scenes/sdfgrid/torus_sdfgrid.vol) placed by a non-uniform scale and a translation, with Mitsuba 3.9.1
`scalar_rgb`, and writes one row per ray: origin, direction, then Mitsuba's t, geometric normal and
smooth shading normal (or `miss`). Run from the repository root:

    .venv/bin/python tools/sdfgrid_reference.py > crates/gonio/tests/data/sdfgrid_torus_hits.tsv
"""

import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")
VOL = "/work/shared/data/mitsuba-scenes/mitsuba-renderer__mitsuba-data/docs/scenes/sdfgrid/torus_sdfgrid.vol"
TO_WORLD = mi.ScalarTransform4f().translate([0.5, -1.0, 0.25]) @ mi.ScalarTransform4f().scale([3.0, 2.0, 2.5])
scene = mi.load_dict({"type": "scene", "s": {"type": "sdfgrid", "filename": VOL, "normals": "smooth", "to_world": TO_WORLD}})
rng = np.random.default_rng(7)
centre = np.array(TO_WORLD @ mi.ScalarPoint3f(0.5, 0.5, 0.5))
print("# ox oy oz dx dy dz t nx ny nz shx shy shz (Mitsuba 3.9.1 scalar_rgb; tools/sdfgrid_reference.py)")
for _ in range(400):
    v = rng.normal(size=3)
    o = centre + 6.0 * v / np.linalg.norm(v)
    target = centre + rng.uniform(-1.2, 1.2, size=3)
    d = target - o
    d /= np.linalg.norm(d)
    si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*o), mi.Vector3f(*d)))
    row = [f"{x:.9g}" for x in (*o, *d)]
    if si.is_valid():
        row += [f"{si.t:.9g}", *(f"{x:.9g}" for x in si.n), *(f"{x:.9g}" for x in si.sh_frame.n)]
    else:
        row += ["miss"]
    print("\t".join(row))
