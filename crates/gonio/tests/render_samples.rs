//! A render split into ranges of sample indices (`render_samples`, what `gonio.distributed` runs on each
//! machine) adds up to the single render: bit for bit when the range is the whole render, and to the last
//! bit of the f32 image for any split (the parts' f64 sums are added in another order; docs/distributed.md).
//! Also: a scene description lists the files it was read from, which is what is shipped with it.

use gonio::film::{Film, Filter};
use gonio::render::{render, render_samples};
use gonio::scene::{mitsuba_xml, Scene};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn bench_scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/scenes").join(name)
}

fn small(name: &str, filter: Filter) -> Scene {
    let defines = [("width".to_string(), "48".to_string()), ("height".to_string(), "36".to_string())];
    let mut scene = Scene::load(&bench_scene(name), &defines).unwrap();
    scene.film.filter = filter;
    scene
}

/// Distance in units in the last place between two non-negative finite f32.
fn ulps(a: f32, b: f32) -> u32 {
    assert!(a >= 0.0 && b >= 0.0 && a.is_finite() && b.is_finite(), "{a} {b}");
    a.to_bits().abs_diff(b.to_bits())
}

fn merged(scene: &Scene, seed: u64, ranges: &[std::ops::Range<u32>]) -> (Vec<f32>, u64) {
    let no = AtomicBool::new(false);
    let mut total: Option<Film> = None;
    let mut nonfinite = 0;
    let mut spp = 0;
    for r in ranges {
        let part = render_samples(scene, seed, r.clone(), &no, &|_| {});
        assert_eq!((part.first, part.spp_done, part.cancelled), (r.start, r.end - r.start, false));
        nonfinite += part.nonfinite;
        spp += part.spp_done;
        match &mut total {
            None => total = Some(part.film),
            Some(t) => t.add_tile(0, 0, &part.film),
        }
    }
    (total.unwrap().mean(spp), nonfinite)
}

#[test]
fn split_renders_add_up_to_the_single_render() {
    for (name, filter) in [("cbox-obj-meshlight.xml", Filter::BOX), ("mask-measured-rectlight.xml", Filter::gaussian(0.5))] {
        let scene = small(name, filter);
        let (spp, seed) = (40, 7);
        let single = render(&scene, spp, seed, &AtomicBool::new(false), &|_| {});
        // One range: the very same sums, so the same image bit for bit.
        let whole_range = 0..spp;
        let (whole, nonfinite) = merged(&scene, seed, std::slice::from_ref(&whole_range));
        assert_eq!(whole, single.data, "{name}: render_samples(0..spp) is render");
        assert_eq!(nonfinite, single.nonfinite);
        // Uneven splits, merged in sample order and out of it: within one unit in the last place of f32
        // (every term is non-negative, so f64 sums in any order agree to ~n·2⁻⁵³ relative), and most
        // pixels identical.
        for ranges in [vec![0..13, 13..29, 29..40], vec![29..40, 0..1, 17..29, 1..17]] {
            let (image, nonfinite) = merged(&scene, seed, &ranges);
            assert_eq!(nonfinite, single.nonfinite);
            let worst = image.iter().zip(&single.data).map(|(a, b)| ulps(*a, *b)).max().unwrap();
            let differ = image.iter().zip(&single.data).filter(|(a, b)| a != b).count();
            assert!(worst <= 1, "{name} {ranges:?}: {worst} ulps");
            assert!(differ * 100 < image.len(), "{name} {ranges:?}: {differ} of {} values differ", image.len());
            // Not a vacuous comparison: the image has light in it.
            assert!(image.iter().filter(|v| **v > 0.0).count() * 2 > image.len(), "{name}");
        }
        // Merging the same parts in the same order is deterministic: bit for bit.
        assert_eq!(merged(&scene, seed, &[0..20, 20..40]).0, merged(&scene, seed, &[0..20, 20..40]).0);
    }
}

#[test]
fn a_part_is_independent_of_the_other_parts() {
    // Samples 10..20 are the same samples whether rendered alone or as part of 0..20 (their own streams):
    // sums(0..20) − sums(0..10) ≈ sums(10..20) to f64 rounding.
    let scene = small("cbox-obj-meshlight.xml", Filter::BOX);
    let no = AtomicBool::new(false);
    let a = render_samples(&scene, 3, 0..10, &no, &|_| {});
    let b = render_samples(&scene, 3, 10..20, &no, &|_| {});
    let ab = render_samples(&scene, 3, 0..20, &no, &|_| {});
    assert_eq!(ab.film.sums().len(), 3 * 48 * 36);
    for ((x, y), z) in a.film.sums().iter().zip(b.film.sums()).zip(ab.film.sums()) {
        assert!((x + y - z).abs() <= 1e-12 * z.abs().max(1e-30), "{x:?} {y:?} {z:?}");
    }
    assert!(a.film.weights().is_none());
    // An empty range sums nothing.
    let none = render_samples(&scene, 3, 5..5, &no, &|_| {});
    assert_eq!((none.spp_done, none.cancelled), (0, false));
    assert!(none.film.sums().iter().all(|s| *s == 0.0));
}

#[test]
fn films_round_trip_through_their_sums() {
    let scene = small("mask-measured-rectlight.xml", Filter::tent(1.0));
    let part = render_samples(&scene, 1, 0..4, &AtomicBool::new(false), &|_| {});
    let flat = part.film.sums();
    let back = Film::from_sums(48, 36, 3, flat, part.film.weights()).unwrap();
    assert_eq!(back, part.film);
    let e = Film::from_sums(48, 36, 3, &flat[3..], None).unwrap_err().to_string();
    assert!(e.contains("a 48×36 film of 3 channels needs 5184 sums"), "{e}");
}

#[test]
fn a_scene_lists_the_files_it_reads() {
    let path = bench_scene("mask-measured-rectlight.xml");
    let desc = mitsuba_xml::load_file(&path, &[]).unwrap();
    let names: Vec<String> = desc.files.iter().map(|f| f.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names[0], "mask-measured-rectlight.xml");
    for asset in ["cc_ibiza_sunset_rgb.bsdf", "vch_golden_yellow_rgb.bsdf"] {
        assert_eq!(names.iter().filter(|n| *n == asset).count(), 1, "{asset} once in {names:?}");
    }
    assert!(names.iter().any(|n| n.ends_with(".png")), "the mask's bitmap: {names:?}");
    assert!(desc.files.iter().all(|f| f.is_file()), "{:?}", desc.files);
}
