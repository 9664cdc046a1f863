//! The fuzz corpora on stable: every committed seed (`fuzz/seeds/<target>/`) and every input that once
//! crashed or hung a loader (`fuzz/regressions/<target>/`) goes through the same function the fuzzer
//! calls ([`gonio::fuzz`]), which must return without a panic. See docs/fuzzing.md.
//!
//! `write_seeds` (ignored; run by hand) regenerates the binary seeds from the real files in
//! `../shared/data`, shrunk to a few KB.

use std::path::{Path, PathBuf};
use std::time::Instant;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(entries) => entries.map(|e| e.unwrap().path()).filter(|p| p.is_file()).collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

#[test]
fn every_seed_and_regression_input_loads_without_panic() {
    let mut failures = Vec::new();
    let mut total = 0;
    for (name, run) in gonio::fuzz::TARGETS {
        let seeds = files_in(&fuzz_dir().join("seeds").join(name));
        assert!(!seeds.is_empty(), "target `{name}` has no committed seeds");
        for file in seeds.iter().chain(&files_in(&fuzz_dir().join("regressions").join(name))) {
            let bytes = std::fs::read(file).unwrap();
            let start = Instant::now();
            if std::panic::catch_unwind(|| run(&bytes)).is_err() {
                failures.push(format!("{name}: {} panicked", file.display()));
            }
            // A generous bound (the fuzzers' own limit is 10 s): a hang is a bug even without a panic.
            let seconds = start.elapsed().as_secs_f64();
            if seconds > 5.0 {
                failures.push(format!("{name}: {} took {seconds:.1} s", file.display()));
            }
            total += 1;
        }
    }
    assert!(failures.is_empty(), "{} of {total} inputs failed:\n{}", failures.len(), failures.join("\n"));
}

/// `roughplastic` is fuzzed (the targets skipped it until 2026-12) without integrating its coating
/// tables, which costs seconds per α and η: inputs with many distinct α and η, valid and not, through
/// both targets that build BSDFs, integrate none (a count, not a clock).
#[test]
fn roughplastic_inputs_are_built_without_integrating_tables() {
    let before = gonio::bsdf::rough_plastic::table_integrations();
    for (i, alpha) in [1e-4, 0.0123, 0.3, 0.77, 10.0, -1.0, 0.0].into_iter().enumerate() {
        let eta = 1.0 + 0.137 * i as f64;
        for distribution in ["ggx", "beckmann"] {
            let spec = format!(
                r#"{{"type": "roughplastic", "distribution": "{distribution}", "alpha": {alpha}, "int_ior": {eta}, "energy_compensation": {}}}"#,
                i % 2 == 0
            );
            gonio::fuzz::bsdf_json(spec.as_bytes());
            let scene = format!(
                r#"<scene version="3.0.0"><shape type="sphere"><bsdf type="roughplastic"><string name="distribution" value="{distribution}"/>
                   <float name="alpha" value="{alpha}"/><float name="int_ior" value="{eta}"/></bsdf></shape></scene>"#
            );
            gonio::fuzz::xml_scene(scene.as_bytes());
        }
    }
    assert_eq!(gonio::bsdf::rough_plastic::table_integrations(), before);
}

// ------------------------------------------------------------------------------------------------
// Seeds from real data, shrunk

const DATA: &str = "/work/shared/data";

fn write(target: &str, name: &str, bytes: &[u8]) {
    let dir = fuzz_dir().join("seeds").join(target);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(name), bytes).unwrap();
}

/// The first `n` triangles of a mesh and the vertices they use, renumbered.
fn shrink(mesh: &gonio::geometry::mesh_io::MeshData, n: usize) -> gonio::geometry::mesh_io::MeshData {
    let mut map = std::collections::HashMap::new();
    let mut out = gonio::geometry::mesh_io::MeshData::default();
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    for tri in mesh.indices.iter().take(n) {
        let t = tri.map(|i| {
            *map.entry(i).or_insert_with(|| {
                out.positions.push(mesh.positions[i as usize]);
                if let Some(n) = &mesh.normals {
                    normals.push(n[i as usize]);
                }
                if let Some(uv) = &mesh.uvs {
                    uvs.push(uv[i as usize]);
                }
                out.positions.len() as u32 - 1
            })
        });
        out.indices.push(t);
    }
    out.normals = mesh.normals.as_ref().map(|_| normals);
    out.uvs = mesh.uvs.as_ref().map(|_| uvs);
    out
}

fn ply_bytes(mesh: &gonio::geometry::mesh_io::MeshData, encoding: &str) -> Vec<u8> {
    let mut header = format!("ply\nformat {encoding} 1.0\ncomment shrunk from a real file\nelement vertex {}\n", mesh.positions.len());
    header += "property float x\nproperty float y\nproperty float z\n";
    if mesh.normals.is_some() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if mesh.uvs.is_some() {
        header += "property float u\nproperty float v\n";
    }
    header += &format!("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.indices.len());
    let mut out = header.into_bytes();
    let big = encoding == "binary_big_endian";
    let put = |out: &mut Vec<u8>, v: f32| {
        if encoding == "ascii" {
            out.extend_from_slice(format!("{v} ").as_bytes());
        } else if big {
            out.extend_from_slice(&v.to_be_bytes());
        } else {
            out.extend_from_slice(&v.to_le_bytes());
        }
    };
    for i in 0..mesh.positions.len() {
        let mut vals = mesh.positions[i].to_array().to_vec();
        if let Some(n) = &mesh.normals {
            vals.extend(n[i].to_array());
        }
        if let Some(uv) = &mesh.uvs {
            vals.extend(uv[i].to_array());
        }
        for v in vals {
            put(&mut out, v);
        }
        if encoding == "ascii" {
            out.push(b'\n');
        }
    }
    for t in &mesh.indices {
        if encoding == "ascii" {
            out.extend_from_slice(format!("3 {} {} {}\n", t[0], t[1], t[2]).as_bytes());
        } else {
            out.push(3);
            for i in t {
                out.extend_from_slice(&if big { (*i as i32).to_be_bytes() } else { (*i as i32).to_le_bytes() });
            }
        }
    }
    out
}

/// One mesh in the `.serialized` layout of gonio::geometry::mesh_io (version 3 or 4).
fn serialized_mesh(mesh: &gonio::geometry::mesh_io::MeshData, version: u16, double: bool) -> Vec<u8> {
    use std::io::Write;
    let mut flags = if double { 0x2000u32 } else { 0x1000 };
    if mesh.normals.is_some() {
        flags |= 1;
    }
    if mesh.uvs.is_some() {
        flags |= 2;
    }
    let mut raw = flags.to_le_bytes().to_vec();
    if version == 4 {
        raw.extend_from_slice(b"shrunk\0");
    }
    raw.extend_from_slice(&(mesh.positions.len() as u64).to_le_bytes());
    raw.extend_from_slice(&(mesh.indices.len() as u64).to_le_bytes());
    let mut put = |v: f32| {
        if double {
            raw.extend_from_slice(&f64::from(v).to_le_bytes());
        } else {
            raw.extend_from_slice(&v.to_le_bytes());
        }
    };
    mesh.positions.iter().flat_map(|p| p.to_array()).for_each(&mut put);
    mesh.normals.iter().flatten().flat_map(|p| p.to_array()).for_each(&mut put);
    mesh.uvs.iter().flatten().flat_map(|p| p.to_array()).for_each(&mut put);
    for i in mesh.indices.iter().flatten() {
        raw.extend_from_slice(&i.to_le_bytes());
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&z.finish().unwrap());
    out
}

/// Meshes one after another, then the dictionary of offsets and the count.
fn serialized_file(meshes: &[Vec<u8>], version: u16) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for m in meshes {
        offsets.push(out.len() as u64);
        out.extend_from_slice(m);
    }
    for o in offsets {
        if version == 4 {
            out.extend_from_slice(&o.to_le_bytes());
        } else {
            out.extend_from_slice(&(o as u32).to_le_bytes());
        }
    }
    out.extend_from_slice(&(meshes.len() as u32).to_le_bytes());
    out
}

/// A smaller RGL file: the first φᵢ, every other θᵢ, every 8th grid point (the densities stay positive,
/// so the loader accepts it).
fn shrink_rgl(path: &Path) -> Vec<u8> {
    use gonio::measured::tensor_file::{encode, f32_bytes, DType, TensorFile};
    let file = TensorFile::open(path).unwrap();
    let theta_keep = |n: usize| (0..n).step_by(3).collect::<Vec<_>>();
    let grid_keep = |n: usize| (0..n).step_by(8).chain(std::iter::once(n - 1)).collect::<std::collections::BTreeSet<_>>();
    let mut fields: Vec<(String, DType, Vec<usize>, Vec<u8>)> = Vec::new();
    for f in file.fields() {
        let name = f.name.as_str();
        match name {
            "description" | "jacobian" => fields.push((name.into(), DType::U8, f.shape.clone(), file.u8_field(name, 1).unwrap().to_vec())),
            "theta_i" => {
                let a = file.f32_field(name, 1).unwrap();
                let keep: Vec<f32> = theta_keep(a.data.len()).iter().map(|&i| a.data[i]).collect();
                fields.push((name.into(), DType::F32, vec![keep.len()], f32_bytes(&keep)));
            }
            "phi_i" => {
                let a = file.f32_field(name, 1).unwrap();
                fields.push((name.into(), DType::F32, vec![1], f32_bytes(&a.data[..1])));
            }
            "ndf" | "sigma" | "vndf" | "luminance" | "rgb" => {
                let a = file.f32_field(name, f.shape.len()).unwrap();
                let s = &a.shape;
                let r = s.len();
                let (gy, gx) = (grid_keep(s[r - 2]), grid_keep(s[r - 1]));
                let lead: Vec<Vec<usize>> = (0..r - 2)
                    .map(|k| match (name, k) {
                        (_, 0) if r > 2 => vec![0],
                        (_, 1) if r > 2 => theta_keep(s[1]),
                        _ => (0..s[k]).collect(),
                    })
                    .collect();
                let mut data = Vec::new();
                let mut shape: Vec<usize> = lead.iter().map(Vec::len).collect();
                shape.extend([gy.len(), gx.len()]);
                let combos: usize = lead.iter().map(Vec::len).product();
                for c in 0..combos {
                    // The c-th combination of kept leading indices, the last dimension fastest.
                    let mut rest = c;
                    let mut idx = vec![0usize; r - 2];
                    for k in (0..r - 2).rev() {
                        idx[k] = lead[k][rest % lead[k].len()];
                        rest /= lead[k].len();
                    }
                    let base = (0..r - 2).fold(0, |acc, k| acc * s[k] + idx[k]);
                    for &y in &gy {
                        for &x in &gx {
                            data.push(a.data[(base * s[r - 2] + y) * s[r - 1] + x]);
                        }
                    }
                }
                fields.push((name.into(), DType::F32, shape, f32_bytes(&data)));
            }
            _ => {}
        }
    }
    let refs: Vec<(&str, DType, &[usize], &[u8])> =
        fields.iter().map(|(n, d, s, b)| (n.as_str(), *d, s.as_slice(), b.as_slice())).collect();
    encode(&refs)
}

fn downsample(img: &gonio::image::Image, w: usize, h: usize) -> gonio::image::Image {
    let mut out = gonio::image::Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            out.set(x, y, img.get(x * img.width / w, y * img.height / h));
        }
    }
    out
}

#[test]
#[ignore = "writes fuzz/seeds from ../shared/data; run by hand"]
fn write_seeds() {
    use gonio::geometry::mesh_io::{load_ply, load_serialized};
    let data = Path::new(DATA);
    let meshes = data.join("mitsuba/common/meshes");
    // OBJ: the small real files whole, the first 3 KB of the sphere (cut at a line).
    for f in ["rectangle.obj", "cbox/smallbox.obj", "cbox/floor.obj", "cbox/luminaire.obj"] {
        write("obj", &f.replace('/', "_"), &std::fs::read(meshes.join(f)).unwrap());
    }
    let sphere = std::fs::read(meshes.join("sphere.obj")).unwrap();
    let cut = sphere[..3000].iter().rposition(|&b| b == b'\n').unwrap();
    write("obj", "sphere_head.obj", &sphere[..=cut]);
    let with_faces: String =
        String::from_utf8_lossy(&sphere).lines().filter(|l| l.starts_with("f ")).take(20).collect::<Vec<_>>().join("\n");
    write("obj", "sphere_faces.obj", with_faces.as_bytes());
    // PLY: the real sphere shrunk to 24 triangles, in all three encodings; its real header.
    let ply = shrink(&load_ply(&meshes.join("sphere.ply")).unwrap(), 24);
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        write("ply", &format!("sphere24_{enc}.ply"), &ply_bytes(&ply, enc));
    }
    let mesh0 = load_serialized(&meshes.join("matpreview.serialized"), 0).unwrap();
    let uv_mesh = shrink(&mesh0, 16);
    write("ply", "matpreview16_normals_uvs_le.ply", &ply_bytes(&uv_mesh, "binary_little_endian"));
    let real_ply = std::fs::read(meshes.join("sphere.ply")).unwrap();
    write("ply", "sphere_head.ply", &real_ply[..1500]);
    // .serialized: real meshes shrunk, versions 3 and 4, single and double precision, several meshes.
    let mesh1 = shrink(&load_serialized(&meshes.join("matpreview.serialized"), 1).unwrap(), 12);
    let m0 = shrink(&mesh0, 12);
    write(
        "serialized",
        "v4_two_meshes.serialized",
        &serialized_file(&[serialized_mesh(&m0, 4, false), serialized_mesh(&mesh1, 4, false)], 4),
    );
    write("serialized", "v3_one_mesh.serialized", &serialized_file(&[serialized_mesh(&m0, 3, false)], 3));
    write("serialized", "v4_double.serialized", &serialized_file(&[serialized_mesh(&mesh1, 4, true)], 4));
    let real = std::fs::read(meshes.join("matpreview.serialized")).unwrap();
    write("serialized", "matpreview_head.serialized", &real[..2048]);
    // MERL: no real file is small; the right header with a few entries, and a wrong one.
    let mut merl: Vec<u8> = [90i32, 90, 180].iter().flat_map(|d| d.to_le_bytes()).collect();
    merl.extend((0..16).flat_map(|i| (f64::from(i) * 0.01).to_le_bytes()));
    write("merl", "header_and_16_entries.binary", &merl);
    write("merl", "tiny_dims.binary", &[2i32, 2, 4].iter().flat_map(|d| d.to_le_bytes()).chain([0u8; 32]).collect::<Vec<_>>());
    // tensor_file: two real RGL materials shrunk (they still load).
    for m in ["paper_white_rgb.bsdf", "cc_ibiza_sunset_rgb.bsdf"] {
        let bytes = shrink_rgl(&data.join("rgl").join(m));
        gonio::bsdf::Measured::from_file(gonio::measured::tensor_file::TensorFile::parse(Path::new(m), bytes.clone()).unwrap())
            .unwrap_or_else(|e| panic!("the shrunk {m} must load: {e}"));
        write("tensor_file", &format!("shrunk_{m}"), &bytes);
    }
    // Images: real maps downsampled and written by gonio; the real headers.
    let scratch = std::env::temp_dir().join(format!("gonio-seeds-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    let museum = gonio::image::read_image(&data.join("envmaps/museum.exr")).unwrap();
    let venice = gonio::image::read_image(&data.join("envmaps/venice_sunset_1k.hdr")).unwrap();
    for (target, ext) in [("exr", "exr"), ("hdr", "hdr"), ("png", "png")] {
        for (name, img) in [("museum", &museum), ("venice", &venice)] {
            let path = scratch.join(format!("{name}.{ext}"));
            gonio::image::write_image(&path, &downsample(img, 8, 4)).unwrap();
            write(target, &format!("{name}_8x4.{ext}"), &std::fs::read(&path).unwrap());
        }
    }
    write("exr", "museum_head.exr", &std::fs::read(data.join("envmaps/museum.exr")).unwrap()[..3000]);
    write("hdr", "venice_head.hdr", &std::fs::read(data.join("envmaps/venice_sunset_1k.hdr")).unwrap()[..3000]);
    write("png", "leaf_mask.png", &std::fs::read(data.join("mitsuba/common/textures/leaf_mask.png")).unwrap());
    // JSON: every model's documented examples that do not read files.
    for (i, spec) in gonio::Bsdf::examples().iter().enumerate() {
        if !spec.contains("filename") {
            write("bsdf_json", &format!("example_{i:02}.json"), spec.as_bytes());
        }
    }
    let _ = std::fs::remove_dir_all(&scratch);
}
