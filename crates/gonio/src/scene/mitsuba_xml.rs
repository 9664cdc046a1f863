//! The Mitsuba 3 XML scene format, document level: `<scene version>`, `<default>` parameters with
//! `$name` substitution and command-line overrides, `<path>` search paths, `<include>`, ids for `<ref>`.
//!
//! Mitsuba 3's rules, which real scenes rely on:
//! - **Files** (meshes, textures, `<include>`s) are searched in the `<path>` folders (the latest first),
//!   then in the *main* scene file's folder, also from inside an included fragment (Mitsuba's file
//!   resolver holds the main file's folder, not the fragment's; `cbox-rgb.xml` includes
//!   `fragments/shapes.xml`, which names `meshes/cbox_luminaire.obj` beside `cbox-rgb.xml`). gonio
//!   searches the fragment's own folder last, after those.
//! - **`<path value>`** is taken relative to the file it is in, or else resolved as a file is.
//! - **`<ref id>`** may name a plugin declared later in the scene (an area emitter declared after the shapes
//!   that use it, a top-level `<sampler id>` used by the sensor): references are resolved once the whole
//!   scene is read.
//!
//! Plugin elements are read by [`Props::from_xml_element_in`]; [`super::Scene::build`] turns the result
//! into a renderable scene.
//!
//! ```
//! let desc = gonio::scene::mitsuba_xml::load_str(r#"<scene version="3.0.0">
//!     <default name="r" value="0.5"/>
//!     <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="$r"/></bsdf></shape>
//! </scene>"#, "doc.xml", std::path::Path::new("."), &[]).unwrap();
//! assert_eq!(desc.shapes.len(), 1);
//! ```

use crate::error::{Error, Result};
use crate::props::Props;
use crate::xml::{xml_at, XmlEnv, XmlSource};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A parsed scene: the top-level plugins, not yet built.
#[derive(Clone, Debug, Default)]
pub struct SceneDescription {
    pub integrator: Option<Props>,
    pub sensor: Option<Props>,
    pub shapes: Vec<Props>,
    pub emitters: Vec<Props>,
    /// Where the scene came from (for messages).
    pub source: String,
    /// Things accepted but worth a note, found while reading (see [`XmlEnv::warnings`]).
    pub warnings: Vec<String>,
    /// The files the scene was read from: the scene file, its `<include>`s, then every asset it names
    /// (meshes, images, measured data, spectra), each once, in the order first read.
    pub files: Vec<PathBuf>,
}

/// Parse a scene file; `overrides` are `-D name=value` pairs that take precedence over `<default>`s.
pub fn load_file(path: &Path, overrides: &[(String, String)]) -> Result<SceneDescription> {
    let mut loader = Loader::new(overrides);
    loader.desc.source = path.display().to_string();
    loader.file(path, None)?;
    loader.finish()
}

/// Parse a scene from text; `source` names it in messages, `dir` resolves relative file names.
pub fn load_str(text: &str, source: &str, dir: &Path, overrides: &[(String, String)]) -> Result<SceneDescription> {
    let mut loader = Loader::new(overrides);
    loader.desc.source = source.to_string();
    loader.document(text, source, dir)?;
    loader.finish()
}

struct Loader {
    env: XmlEnv,
    /// `<path>` directories, most recent first (Mitsuba prepends them).
    paths: Vec<PathBuf>,
    /// The main scene file's folder (set by the first document read).
    main_dir: Option<PathBuf>,
    desc: SceneDescription,
    /// Files being included, to reject include cycles.
    stack: Vec<PathBuf>,
    /// Files read by `<include>` so far, and plugins in the document so far (with references expanded).
    included: usize,
    plugins: usize,
}

/// At most this many `<include>`s in one load, counting repeats (2026-11, issue 8: a file that includes
/// the next one twice, ten deep, is read 2¹⁰ times)...
pub const MAX_INCLUDES: usize = 256;
/// ...and at most [`MAX_PLUGINS`] plugins in the whole document once references are expanded.
pub use crate::props::MAX_PLUGINS;

impl Loader {
    fn new(overrides: &[(String, String)]) -> Self {
        let mut env = XmlEnv::default();
        env.params.extend(overrides.iter().cloned());
        env.forward_refs = true;
        Loader { env, paths: Vec::new(), main_dir: None, desc: SceneDescription::default(), stack: Vec::new(), included: 0, plugins: 0 }
    }

    /// Resolve the references to plugins declared after them, now that every id is known.
    fn finish(mut self) -> Result<SceneDescription> {
        let mut resolver = RefResolver { declared: &self.env.refs, done: HashMap::new(), active: Vec::new() };
        let desc = &mut self.desc;
        let tops = desc.integrator.iter_mut().chain(desc.sensor.iter_mut()).chain(desc.shapes.iter_mut()).chain(desc.emitters.iter_mut());
        for p in tops.filter(|p| p.has_forward_refs()) {
            let before = p.plugin_count();
            p.resolve_refs(&mut |id, at| resolver.get(id, at))?;
            self.plugins += p.plugin_count() - before;
            if self.plugins > MAX_PLUGINS {
                return Err(Error::spec(p.at(), format!("more than {MAX_PLUGINS} plugins in the scene once references are expanded")));
            }
        }
        self.desc.warnings = self.env.warnings.take();
        for f in self.env.files.take() {
            if !self.desc.files.contains(&f) {
                self.desc.files.push(f);
            }
        }
        Ok(self.desc)
    }

    fn file(&mut self, path: &Path, included_at: Option<&str>) -> Result<()> {
        let text = std::fs::read_to_string(path).map_err(|source| match included_at {
            Some(at) => Error::spec(at, format!("cannot read included file `{}`: {source}", path.display())),
            None => Error::Io { path: path.to_path_buf(), source },
        })?;
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        if self.stack.contains(&canonical) {
            return Err(Error::spec(included_at.unwrap_or("?"), format!("`{}` includes itself", path.display())));
        }
        self.stack.push(canonical);
        self.desc.files.push(path.to_path_buf());
        // A bare file name has the parent "", which would print as an empty search path.
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let result = self.document(&text, &path.display().to_string(), &dir);
        self.stack.pop();
        result
    }

    /// The directories a relative file name in a file of directory `dir` is searched in: the `<path>`s,
    /// the main file's folder, then `dir` (module docs).
    fn search_paths(&self, dir: &Path) -> Vec<PathBuf> {
        let mut all = self.paths.clone();
        all.extend(self.main_dir.iter().cloned());
        if self.main_dir.as_deref() != Some(dir) {
            all.push(dir.to_path_buf());
        }
        all
    }

    /// A top-level plugin element, counted against [`MAX_PLUGINS`].
    fn plugin(&mut self, node: roxmltree::Node, source: &XmlSource, at: &str) -> Result<Props> {
        let props = Props::from_xml_element_in(node, source, &self.env)?;
        self.plugins += props.plugin_count();
        if self.plugins > MAX_PLUGINS {
            return Err(Error::spec(at, format!("more than {MAX_PLUGINS} plugins in the scene once references are expanded")));
        }
        Ok(props)
    }

    fn document(&mut self, text: &str, source: &str, dir: &Path) -> Result<()> {
        let doc = crate::xml::parse_document(text, source)?;
        let source = &XmlSource::new(source, text);
        if self.main_dir.is_none() {
            self.main_dir = Some(dir.to_path_buf());
        }
        let root = doc.root_element();
        let at = xml_at(source, root);
        if !root.has_tag_name("scene") {
            return Err(Error::spec(at, format!("expected a <scene> root element, found <{}>", root.tag_name().name())));
        }
        let version =
            root.attribute("version").ok_or_else(|| Error::spec(&at, "<scene> needs a version attribute (e.g. version=\"3.0.0\")"))?;
        if !version.split('.').next().is_some_and(|major| matches!(major, "0" | "2" | "3")) {
            return Err(Error::spec(&at, format!("unsupported scene version \"{version}\" (gonio reads Mitsuba 2 and 3 scenes)")));
        }
        for node in root.children().filter(roxmltree::Node::is_element) {
            let at = xml_at(source, node);
            self.env.search_paths = self.search_paths(dir);
            match node.tag_name().name() {
                "default" => {
                    let name = self.env.required(node, "name", source)?;
                    let value = self.env.required(node, "value", source)?;
                    self.env.params.entry(name).or_insert(value);
                }
                "path" => {
                    let value = self.env.required(node, "value", source)?;
                    // Relative to this file, else resolved as a file name is (Mitsuba 3 does the same).
                    let here = dir.join(&value);
                    let p = if here.is_dir() {
                        here
                    } else {
                        let found = self.env.search_paths.iter().map(|d| d.join(&value)).find(|p| p.is_dir());
                        found.ok_or_else(|| {
                            let dirs: Vec<String> = self.env.search_paths.iter().map(|d| d.display().to_string()).collect();
                            Error::spec(at, format!("<path>: no directory `{value}` (searched: {})", dirs.join(", ")))
                        })?
                    };
                    self.paths.insert(0, p);
                }
                "include" => {
                    let name = self.env.required(node, "filename", source)?;
                    let path = self.env.resolve_file(&name, &at)?;
                    self.included += 1;
                    if self.included > MAX_INCLUDES {
                        return Err(Error::spec(at, format!("more than {MAX_INCLUDES} <include>s in one scene")));
                    }
                    self.file(&path, Some(&at))?;
                }
                "integrator" | "sensor" => {
                    let props = self.plugin(node, source, &at)?;
                    let slot = if node.has_tag_name("sensor") { &mut self.desc.sensor } else { &mut self.desc.integrator };
                    if let Some(prev) = slot {
                        return Err(Error::spec(at, format!("a second <{}>; the first is at {}", node.tag_name().name(), prev.at())));
                    }
                    *slot = Some(props);
                }
                tag @ ("shape" | "emitter" | "bsdf" | "texture" | "sampler" | "film" | "rfilter") => {
                    let props = self.plugin(node, source, &at)?;
                    if let Some(id) = props.id() {
                        self.env.refs.insert(id.to_string(), props.clone());
                    }
                    match tag {
                        "shape" => self.desc.shapes.push(props),
                        // An `area` emitter at the top level is a declaration for the shapes that
                        // `<ref>` it (Mitsuba 3 scenes do this), not a light of its own.
                        "emitter" if props.plugin_type() == "area" && props.id().is_some() => {}
                        "emitter" => self.desc.emitters.push(props),
                        "sampler" | "film" | "rfilter" if props.id().is_none() => {
                            return Err(Error::spec(
                                at,
                                format!("a top-level <{tag}> is used by a <ref id=\"…\"> in the sensor: give it an id"),
                            ))
                        }
                        _ => {}
                    }
                }
                other => return Err(Error::spec(at, format!("unsupported element <{other}> in <scene>"))),
            }
        }
        Ok(())
    }
}

/// The plugins declared with an id, each resolved once (its own forward references replaced) when first
/// asked for; a cycle of references is an error.
struct RefResolver<'a> {
    declared: &'a HashMap<String, Props>,
    done: HashMap<String, Props>,
    active: Vec<String>,
}

impl RefResolver<'_> {
    fn get(&mut self, id: &str, at: &str) -> Result<Props> {
        if let Some(p) = self.done.get(id) {
            return Ok(p.clone());
        }
        if self.active.iter().any(|a| a == id) {
            return Err(Error::spec(at, format!("<ref id=\"{id}\">: the plugin refers to itself (through {})", self.active.join(" → "))));
        }
        let mut p = self
            .declared
            .get(id)
            .cloned()
            .ok_or_else(|| Error::spec(at, format!("<ref id=\"{id}\">: no plugin with this id is declared in the scene")))?;
        self.active.push(id.to_string());
        p.resolve_refs(&mut |id, at| self.get(id, at))?;
        self.active.pop();
        self.done.insert(id.to_string(), p.clone());
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    fn scratch(tag: &str) -> crate::scratch::ScratchDir {
        crate::scratch::ScratchDir::new(&format!("xml-{tag}"))
    }

    /// The error of loading `text`, which must come in bounded time (a generous bound: the point is that
    /// without the limits these inputs take hours or exhaust memory; the machine running tests is shared).
    fn refused(text: &str, dir: &Path) -> String {
        let start = Instant::now();
        let e = match load_str(text, "h.xml", dir, &[]) {
            Ok(_) => panic!("accepted: {}", &text[..text.len().min(200)]),
            Err(e) => e.to_string(),
        };
        assert!(start.elapsed().as_secs_f64() < 20.0, "{e}: took {:?}", start.elapsed());
        e
    }

    const SCENE: &str = "<scene version=\"3.0.0\">";

    #[test]
    fn include_cycles_and_fan_outs_are_errors() {
        let dir = scratch("includes");
        std::fs::write(dir.join("a.xml"), format!("{SCENE}<include filename=\"b.xml\"/></scene>")).unwrap();
        std::fs::write(dir.join("b.xml"), format!("{SCENE}<include filename=\"a.xml\"/></scene>")).unwrap();
        let e = refused(&format!("{SCENE}\n<include filename=\"a.xml\"/></scene>"), &dir);
        assert!(e.contains("a.xml` includes itself"), "{e}");
        // Each file includes the next twice: 2²⁰ reads without the limit.
        for i in 0..20 {
            let inc = format!("<include filename=\"f{}.xml\"/>", i + 1);
            std::fs::write(dir.join(format!("f{i}.xml")), format!("{SCENE}{inc}{inc}</scene>")).unwrap();
        }
        std::fs::write(dir.join("f20.xml"), format!("{SCENE}</scene>")).unwrap();
        let e = refused(&format!("{SCENE}<include filename=\"f0.xml\"/></scene>"), &dir);
        assert!(e.contains(&format!("more than {MAX_INCLUDES} <include>s")), "{e}");
    }

    #[test]
    fn expansion_bombs_are_errors() {
        let dir = scratch("bombs");
        // Entities: roxmltree refuses any DTD.
        let laughs = "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [<!ENTITY lol \"lol\"><!ENTITY lol1 \"&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;\">\
                      <!ENTITY lol2 \"&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;\">]>\n<scene version=\"3.0.0\">&lol2;</scene>";
        let e = refused(laughs, &dir);
        assert!(e.starts_with("h.xml:1:") && e.contains("not valid XML") && e.contains("DTD"), "{e}");
        // The same with defaults: each repeats the previous one ten times.
        let mut text = format!("{SCENE}<default name=\"d0\" value=\"lol\"/>");
        for i in 1..10 {
            text += &format!("\n<default name=\"d{i}\" value=\"{}\"/>", format!("$d{}", i - 1).repeat(10));
        }
        let e = refused(&(text + "</scene>"), &dir);
        assert!(e.contains(&format!("expands to more than {} bytes", crate::xml::MAX_SUBSTITUTED_VALUE)), "{e}");
        // References: each plugin refers to the previous one twice (2⁴⁰ copies without the limit).
        let mut text = format!("{SCENE}<bsdf type=\"diffuse\" id=\"b0\"/>");
        for i in 1..40 {
            text += &format!("\n<bsdf type=\"blendbsdf\" id=\"b{i}\"><ref id=\"b{0}\"/><ref id=\"b{0}\"/></bsdf>", i - 1);
        }
        let e = refused(&(text + "</scene>"), &dir);
        assert!(e.contains(&format!("more than {MAX_PLUGINS} plugins")), "{e}");
        // Many small ones at the top level count too.
        let mut text = format!("{SCENE}<bsdf type=\"diffuse\" id=\"b0\"/>");
        for i in 1..12 {
            text += &format!("\n<bsdf type=\"blendbsdf\" id=\"b{i}\"><ref id=\"b{0}\"/><ref id=\"b{0}\"/></bsdf>", i - 1);
        }
        text += &"<shape type=\"sphere\"><ref id=\"b11\"/></shape>".repeat(200);
        let e = refused(&(text + "</scene>"), &dir);
        assert!(e.contains("plugins in the scene"), "{e}");
    }

    #[test]
    fn deep_nesting_and_wide_plugins_are_errors() {
        let dir = scratch("deep");
        // Plugins 100 deep: the plugin reader's limit. Elements 100 000 deep: caught before `roxmltree`,
        // whose recursive tokenizer overflowed the stack here (an abort, not even a panic).
        for (depth, want) in [(100, "plugins nested more than 64 deep".to_string()), (100_000, "elements nested more than 256 deep".into())]
        {
            let text = format!("{SCENE}{}{}</scene>", "<bsdf type=\"twosided\">".repeat(depth), "</bsdf>".repeat(depth));
            let e = refused(&text, &dir);
            assert!(e.starts_with("h.xml:1:") && e.contains(&want), "{e}");
        }
        let params: String = (0..1100).map(|i| format!("<float name=\"p{i}\" value=\"1\"/>")).collect();
        let e = refused(&format!("{SCENE}<bsdf type=\"diffuse\">{params}</bsdf></scene>"), &dir);
        assert!(e.contains(&format!("more than {} parameters", crate::props::MAX_PARAMETERS)), "{e}");
    }

    /// A scene of `shapes` spheres, 4 elements each, on one line per shape; `broken` spoils the last one.
    fn many_spheres(shapes: usize, broken: bool) -> String {
        let mut text = format!("{SCENE}\n");
        for i in 0..shapes {
            let radius = if broken && i + 1 == shapes { "wide" } else { "0.01" };
            text += &format!(
                "<shape type=\"sphere\"><point name=\"center\" x=\"{i}\" y=\"0\" z=\"0\"/><float name=\"radius\" value=\"{radius}\"/>\
                 <bsdf type=\"diffuse\"/></shape>\n"
            );
        }
        text + "</scene>"
    }

    /// The position work (line-index builds, bytes indexed, lookups and binary-search steps) of `load`.
    fn position_work<T>(load: impl FnOnce() -> T) -> (T, crate::xml::PositionWork) {
        let before = crate::xml::PositionWork::current();
        let out = load();
        let after = crate::xml::PositionWork::current();
        let work = crate::xml::PositionWork {
            builds: after.builds - before.builds,
            bytes_indexed: after.bytes_indexed - before.bytes_indexed,
            lookups: after.lookups - before.lookups,
            steps: after.steps - before.steps,
        };
        (out, work)
    }

    /// Every element's "file:line:col" is computed as it is read; with a scan from the start of the text
    /// per lookup (`roxmltree`'s `text_pos_at`, used until 2026-11) a load was quadratic in the file size.
    /// Now one line index is built per document and each lookup is two binary searches: the work counted
    /// here (deterministic, not a clock) is linear in the size, for a scene that loads and for one whose
    /// last element is an error.
    #[test]
    fn large_scenes_cost_linear_position_work() {
        let mut per_byte = Vec::new();
        for shapes in [25_000, 50_000] {
            let text = many_spheres(shapes, false);
            let (desc, work) = position_work(|| load_str(&text, "big.xml", Path::new("."), &[]));
            assert_eq!(desc.unwrap().shapes.len(), shapes);
            assert_eq!((work.builds, work.bytes_indexed), (1, text.len()), "one line index per document");
            // 10⁵ elements or more, each looked up at least once...
            assert!(work.lookups >= 4 * shapes, "{work:?}");
            // ...each in O(log n) steps: ⌈log₂⌉ + 1 per binary search, three searches.
            let log2 = (usize::BITS - text.len().leading_zeros()) as usize + 1;
            assert!(work.steps <= 3 * log2 * work.lookups, "{work:?}");
            // A scan from the start would cost about lookups × len / 2 bytes: ~10¹¹ here.
            let total = work.bytes_indexed + work.steps;
            eprintln!("{shapes} spheres, {} bytes: {work:?}, {:.2e} per byte", text.len(), total as f64 / text.len() as f64);
            per_byte.push(total as f64 / text.len() as f64);
        }
        // Twice the file, the same work per byte (the steps grow by one per search: a log factor).
        assert!(per_byte[1] < 1.1 * per_byte[0], "position work per byte {per_byte:?}");

        let text = many_spheres(50_000, true);
        let (result, work) = position_work(|| load_str(&text, "big.xml", Path::new("."), &[]));
        let e = result.unwrap_err().to_string();
        assert!(e.starts_with("big.xml:50001:66: <float name=\"radius\">: expected a number, got \"wide\""), "{e}");
        assert_eq!(work.builds, 1);
    }

    /// Mitsuba 3's rules (module docs): a fragment's files, `<include>`s and `<path>`s resolve against the
    /// main file's folder; `<ref>`s may name plugins declared later (an area emitter after its shape, a
    /// top-level sampler after the sensor).
    #[test]
    fn fragments_resolve_against_the_main_folder_and_refs_may_come_later() {
        let dir = scratch("fragments");
        for sub in ["scenes/include", "scenes/meshes", "common/more"] {
            std::fs::create_dir_all(dir.join(sub)).unwrap();
        }
        std::fs::write(dir.join("scenes/meshes/tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        std::fs::write(dir.join("common/more/light.xml"), format!("{SCENE}<emitter type=\"point\"/></scene>")).unwrap();
        // `../common` is not beside the fragment (scenes/common) but beside the main file's folder.
        std::fs::write(
            dir.join("scenes/include/shapes.xml"),
            format!(
                "{SCENE}<path value=\"../common\"/><include filename=\"more/light.xml\"/>\n\
                 <shape type=\"obj\"><string name=\"filename\" value=\"meshes/tri.obj\"/><ref id=\"glow\"/></shape></scene>"
            ),
        )
        .unwrap();
        std::fs::write(
            dir.join("scenes/main.xml"),
            format!(
                "{SCENE}<sensor type=\"perspective\"><ref id=\"spp7\"/></sensor>\n<include filename=\"include/shapes.xml\"/>\n\
                 <emitter type=\"area\" id=\"glow\"><rgb name=\"radiance\" value=\"2\"/></emitter>\n\
                 <sampler type=\"independent\" id=\"spp7\"><integer name=\"sample_count\" value=\"7\"/></sampler></scene>"
            ),
        )
        .unwrap();
        let scene = crate::scene::Scene::build(load_file(&dir.join("scenes/main.xml"), &[]).unwrap()).unwrap();
        assert_eq!(scene.sampler.sample_count, 7);
        assert_eq!(scene.lights.len(), 2, "the area light on the triangle and the included point light");
        assert!(matches!(scene.lights[0], crate::light::Light::Area(ref a) if a.radiance == crate::spectrum::Rgb::splat(2.0)));

        // An id declared nowhere, and references that go round in a circle, are errors at the <ref>.
        let e = refused(&format!("{SCENE}\n<shape type=\"sphere\">\n  <ref id=\"nowhere\"/></shape></scene>"), &dir);
        assert!(e.starts_with("h.xml:3:3: <ref id=\"nowhere\">: no plugin with this id is declared"), "{e}");
        let e = refused(
            &format!(
                "{SCENE}<shape type=\"sphere\"><ref id=\"a\"/></shape>\n<bsdf type=\"twosided\" id=\"a\"><ref id=\"b\"/></bsdf>\n\
                 <bsdf type=\"twosided\" id=\"b\"><ref id=\"a\"/></bsdf></scene>"
            ),
            &dir,
        );
        assert!(e.contains("the plugin refers to itself (through a → b)"), "{e}");
        let e = refused(&format!("{SCENE}\n<sampler type=\"independent\"/></scene>"), &dir);
        assert!(e.starts_with("h.xml:2:1: a top-level <sampler> is used by a <ref"), "{e}");
    }

    #[test]
    fn absurd_resolutions_are_errors() {
        let film = |w: &str, h: &str| {
            format!(
                "{SCENE}<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"{w}\"/>\
                 <integer name=\"height\" value=\"{h}\"/></film></sensor></scene>"
            )
        };
        let build = |text: String| {
            let start = Instant::now();
            let e = load_str(&text, "r.xml", Path::new("."), &[]).and_then(crate::scene::Scene::build).unwrap_err().to_string();
            assert!(start.elapsed().as_secs_f64() < 20.0);
            e
        };
        let e = build(film("99999999999999999999999", "4"));
        assert!(e.starts_with("r.xml:1:") && e.contains("expected an integer"), "{e}");
        let e = build(film("1000000", "1000000"));
        assert!(e.contains("`width`") && e.contains("65536"), "{e}");
        let e = build(film("65536", "65536"));
        assert!(e.contains("a 65536×65536 film has more than 67108864 pixels (e.g. 8192×8192), the most gonio renders"), "{e}");
        let largest = load_str(&film("8192", "8192"), "r.xml", Path::new("."), &[]).and_then(crate::scene::Scene::build).unwrap();
        assert_eq!((largest.film.width, largest.film.height), (8192, 8192));
    }
}
