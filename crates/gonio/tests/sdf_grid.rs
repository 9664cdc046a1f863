//! The `sdfgrid` shape against Mitsuba 3.9.1: the first hit, geometric normal and smooth shading normal
//! of 400 rays on the torus grid of mitsuba-data (`docs/scenes/sdfgrid/torus_sdfgrid.vol`, 40³ samples,
//! in `../shared/data/mitsuba-scenes`), placed by a non-uniform scale and a translation, traced through
//! gonio's scene (BVH over the voxels) and through Mitsuba's `scalar_rgb` (`tools/sdfgrid_reference.py`
//! wrote `data/sdfgrid_torus_hits.tsv`); and the errors for grids that make no shape.

use gonio::geometry::sdf_grid::{read_vol, SdfGrid, SdfGridError};
use gonio::geometry::Ray;
use gonio::math::{Transform, Vec3};
use gonio::scene::{mitsuba_xml, Scene};
use std::path::Path;

const VOL: &str = "/work/shared/data/mitsuba-scenes/mitsuba-renderer__mitsuba-data/docs/scenes/sdfgrid/torus_sdfgrid.vol";

fn scene(normals: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0"><sensor type="perspective"/>
            <shape type="sdfgrid"><string name="filename" value="{VOL}"/><string name="normals" value="{normals}"/>
                <transform name="to_world"><scale x="3" y="2" z="2.5"/><translate x="0.5" y="-1" z="0.25"/></transform>
            </shape></scene>"#
    );
    Scene::build(mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[]).unwrap()).unwrap()
}

fn vec(v: &[f32]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// Every ray hits where Mitsuba's does (t within 10⁻⁵ relative: both solve to ~10⁻⁵ of a voxel) and misses
/// where it misses; the geometric normal agrees within 10⁻⁴ and the smooth one within 2·10⁻⁴ (both are
/// f32 sums of differences of the samples, near 20 in size, rounded differently by the two; measured 4·10⁻⁵).
#[test]
fn sdf_grid_matches_mitsuba() {
    let (smooth, analytic) = (scene("smooth"), scene("analytic"));
    let table = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/sdfgrid_torus_hits.tsv")).unwrap();
    let (mut hits, mut misses, mut worst) = (0, 0, [0.0f32; 3]);
    for (i, line) in table.lines().filter(|l| !l.starts_with('#')).enumerate() {
        let cols: Vec<&str> = line.split('\t').collect();
        let nums: Vec<f32> = cols.iter().filter_map(|c| c.parse().ok()).collect();
        let ray = Ray::new(vec(&nums[0..3]), vec(&nums[3..6]), f32::INFINITY);
        let got = smooth.intersect(&ray);
        if cols[6] == "miss" {
            assert!(got.is_none(), "ray {i}: gonio hits at {got:?}, Mitsuba misses");
            misses += 1;
            continue;
        }
        let got = got.unwrap_or_else(|| panic!("ray {i}: gonio misses, Mitsuba hits at t = {}", nums[6]));
        let (t, n, sh) = (nums[6], vec(&nums[7..10]), vec(&nums[10..13]));
        let errors = [(got.t - t).abs() / t, (got.n - n).length(), (got.shading.n - sh).length()];
        assert!(errors[0] < 1e-5 && errors[1] < 1e-4 && errors[2] < 2e-4, "ray {i}: {errors:?}");
        let flat = analytic.intersect(&ray).unwrap();
        assert!((flat.shading.n - n).length() < 1e-4 && flat.t == got.t, "ray {i}: analytic shading is the geometric normal");
        for (w, e) in worst.iter_mut().zip(errors) {
            *w = w.max(e);
        }
        hits += 1;
    }
    assert!(hits > 100 && misses > 100, "{hits} hits, {misses} misses");
    eprintln!("{hits} hits, {misses} misses; worst: t {:.1e} relative, normal {:.1e}, shading normal {:.1e}", worst[0], worst[1], worst[2]);
}

/// A file that is no grid, a grid without a surface, and a grid as an area light are errors at the place.
#[test]
fn bad_grids_are_errors() {
    assert!(read_vol(b"VOX").unwrap_err().contains("not a grid volume file"));
    let mut bytes = std::fs::read(VOL).unwrap();
    bytes.truncate(bytes.len() - 4);
    assert!(read_vol(&bytes).unwrap_err().contains("255996 bytes of samples for a 40 × 40 × 40 grid"));
    bytes[20] = 3;
    assert!(read_vol(&bytes).unwrap_err().contains("3 channels, expected 1"));
    let positive = SdfGrid::new([2, 2, 2], vec![1.0; 8], Transform::IDENTITY, true, false).unwrap_err();
    assert_eq!(positive, SdfGridError::Empty);
    assert!(matches!(SdfGrid::new([2, 2, 1], vec![1.0; 4], Transform::IDENTITY, true, false), Err(SdfGridError::Size(_))));
    let text = format!(
        r#"<scene version="3.0.0"><sensor type="perspective"/>
            <shape type="sdfgrid"><string name="filename" value="{VOL}"/><emitter type="area"/></shape></scene>"#
    );
    let e = Scene::build(mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[]).unwrap()).err().map(|e| e.to_string());
    assert!(e.as_deref().is_some_and(|e| e.contains("t.xml:2:") && e.contains("cannot be an area light")), "{e:?}");
    let text = text.replace(r#"<emitter type="area"/>"#, r#"<string name="normals" value="flat"/>"#);
    let e = Scene::build(mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[]).unwrap()).err().map(|e| e.to_string());
    assert!(e.as_deref().is_some_and(|e| e.contains("`normals` is `smooth` or `analytic`, got `flat`")), "{e:?}");
}
