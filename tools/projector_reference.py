"""Reference values for gonio's test `flower_projection_matches_mitsuba` (crates/gonio/src/light/projector.rs):
the light Mitsuba 3.9.1 `scalar_rgb`'s `projector` of mitsuba-data's docs/scenes/emitter_projector_textured.xml
delivers (`sample_direction`'s value) at twelve points in front of it, one Rust tuple per line.

    .venv/bin/python tools/projector_reference.py
"""
import mitsuba as mi
mi.set_variant('scalar_rgb')
F="/work/shared/data/mitsuba-scenes/mitsuba-renderer__mitsuba-data/common/textures/flower.bmp"
em=mi.load_dict({'type':'projector','fov':32,'scale':85.8,'irradiance':{'type':'bitmap','filename':F},
  'to_world':mi.ScalarTransform4f().look_at(origin=[4,0,5.5],target=[0,0,1],up=[-1,0,0])})
import numpy as np
rng=np.random.default_rng(3)
for i in range(12):
    p=np.array([0,0,1.0])+np.array([rng.uniform(-1.2,1.2),rng.uniform(-0.9,0.9),rng.uniform(-0.3,0.3)])
    it=mi.Interaction3f(); it.p=mi.Point3f(*p)
    ds,spec=em.sample_direction(it, mi.Point2f(0.5,0.5))
    print(f"({p[0]:.6f}, {p[1]:.6f}, {p[2]:.6f}, [{spec[0]:.7g}, {spec[1]:.7g}, {spec[2]:.7g}]),")
