//! The Mitsuba 3 XML scene format, document level: `<scene version>`, `<default>` parameters with
//! `$name` substitution and command-line overrides, `<path>` search paths, `<include>`, ids for `<ref>`.
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
use crate::xml::{xml_at, XmlEnv};
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
}

/// Parse a scene file; `overrides` are `-D name=value` pairs that take precedence over `<default>`s.
pub fn load_file(path: &Path, overrides: &[(String, String)]) -> Result<SceneDescription> {
    let mut loader = Loader::new(overrides);
    loader.desc.source = path.display().to_string();
    loader.file(path, None)?;
    Ok(loader.desc)
}

/// Parse a scene from text; `source` names it in messages, `dir` resolves relative file names.
pub fn load_str(text: &str, source: &str, dir: &Path, overrides: &[(String, String)]) -> Result<SceneDescription> {
    let mut loader = Loader::new(overrides);
    loader.desc.source = source.to_string();
    loader.document(text, source, dir)?;
    Ok(loader.desc)
}

struct Loader {
    env: XmlEnv,
    /// `<path>` directories, most recent first (Mitsuba prepends them).
    paths: Vec<PathBuf>,
    desc: SceneDescription,
    /// Files being included, to reject include cycles.
    stack: Vec<PathBuf>,
}

impl Loader {
    fn new(overrides: &[(String, String)]) -> Self {
        let mut env = XmlEnv::default();
        env.params.extend(overrides.iter().cloned());
        Loader { env, paths: Vec::new(), desc: SceneDescription::default(), stack: Vec::new() }
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
        // A bare file name has the parent "", which would print as an empty search path.
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let result = self.document(&text, &path.display().to_string(), &dir);
        self.stack.pop();
        result
    }

    /// The directories a relative file name in a file of directory `dir` is searched in.
    fn search_paths(&self, dir: &Path) -> Vec<PathBuf> {
        let mut all = self.paths.clone();
        all.push(dir.to_path_buf());
        all
    }

    fn document(&mut self, text: &str, source: &str, dir: &Path) -> Result<()> {
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let p = e.pos();
            Error::Syntax { at: format!("{source}:{}:{}", p.row, p.col), message: format!("not valid XML: {e}") }
        })?;
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
                    let p = dir.join(value);
                    if !p.is_dir() {
                        return Err(Error::spec(at, format!("<path>: `{}` is not a directory", p.display())));
                    }
                    self.paths.insert(0, p);
                }
                "include" => {
                    let name = self.env.required(node, "filename", source)?;
                    let path = self.env.resolve_file(&name, &at)?;
                    self.file(&path, Some(&at))?;
                }
                "integrator" | "sensor" => {
                    let props = Props::from_xml_element_in(node, source, &self.env)?;
                    let slot = if node.has_tag_name("sensor") { &mut self.desc.sensor } else { &mut self.desc.integrator };
                    if let Some(prev) = slot {
                        return Err(Error::spec(at, format!("a second <{}>; the first is at {}", node.tag_name().name(), prev.at())));
                    }
                    *slot = Some(props);
                }
                tag @ ("shape" | "emitter" | "bsdf" | "texture") => {
                    let props = Props::from_xml_element_in(node, source, &self.env)?;
                    if let Some(id) = props.id() {
                        self.env.refs.insert(id.to_string(), props.clone());
                    }
                    match tag {
                        "shape" => self.desc.shapes.push(props),
                        "emitter" => self.desc.emitters.push(props),
                        _ => {}
                    }
                }
                other => return Err(Error::spec(at, format!("unsupported element <{other}> in <scene>"))),
            }
        }
        Ok(())
    }
}
