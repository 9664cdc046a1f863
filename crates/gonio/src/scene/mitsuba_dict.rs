//! Mitsuba 3's scene dictionary (`mitsuba.load_dict`), as a JSON tree: the same plugins as the XML
//! format, so [`super::Scene::build`] reads both.
//!
//! | dictionary                                             | XML equivalent                                  |
//! |--------------------------------------------------------|-------------------------------------------------|
//! | `{"type": "scene", "key": {...}, …}`                   | `<scene version="3.0.0">…</scene>`              |
//! | `"key": {"type": "sphere", …}` (top level)             | `<shape type="sphere" id="key">` (the key is the id unless `"id"` is given) |
//! | `"film": {"type": "hdrfilm", …}` (any key, nested)     | `<film type="hdrfilm">` inside the parent       |
//! | `"to_world": [[…4 numbers…], …4 rows…]`                | `<transform name="to_world"><matrix value="…"/>` |
//! | `"center": [x, y, z]`                                  | `<point name="center" …/>`                      |
//! | `{"type": "rgb", "value": [r, g, b]}`, `[r, g, b]`, `0.5` | `<rgb …/>`, `<float …/>`                     |
//! | `{"type": "ref", "id": "key"}`                         | `<ref id="key"/>`                               |
//!
//! The class of a plugin (the XML tag) comes from its type, as in Mitsuba's plugin registry: the table
//! below lists Mitsuba 3's plugin names per class, plus gonio's own BSDFs; whether gonio *implements* a
//! plugin is decided by the builder, which names what it has. A reference may point to any plugin of the
//! dictionary, declared before or after it (top-level keys and explicit `"id"`s); cycles are errors.
//!
//! ```
//! let dict = serde_json::json!({
//!     "type": "scene",
//!     "white": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.8, 0.8, 0.8]}},
//!     "ball": {"type": "sphere", "radius": 0.5, "bsdf": {"type": "ref", "id": "white"}},
//!     "camera": {"type": "perspective", "film": {"type": "hdrfilm", "width": 32, "height": 24}},
//! });
//! let desc = gonio::scene::mitsuba_dict::load_value(&dict, "dict").unwrap();
//! let scene = gonio::scene::Scene::build(desc).unwrap();
//! assert_eq!((scene.film.width, scene.shapes.len()), (32, 1));
//! ```

use super::mitsuba_xml::SceneDescription;
use crate::bsdf::PLUGINS;
use crate::error::{Error, Result};
use crate::props::{JsonScope, Props, MAX_PLUGINS};
use serde_json::Value as J;
use std::cell::RefCell;
use std::collections::HashMap;

/// Mitsuba 3's plugin names by class (the XML tag). gonio's own BSDF names come from [`PLUGINS`].
const CLASSES: &[(&str, &[&str])] = &[
    (
        "shape",
        &[
            "obj",
            "ply",
            "serialized",
            "sphere",
            "disk",
            "rectangle",
            "cube",
            "cylinder",
            "bsplinecurve",
            "linearcurve",
            "sdfgrid",
            "shapegroup",
            "instance",
            "ellipsoids",
            "ellipsoidsmesh",
        ],
    ),
    ("emitter", &["area", "point", "constant", "envmap", "spot", "projector", "directional", "directionalarea"]),
    ("sensor", &["perspective", "thinlens", "orthographic", "radiancemeter", "irradiancemeter", "distant", "batch"]),
    ("film", &["hdrfilm", "specfilm"]),
    ("sampler", &["independent", "stratified", "multijitter", "orthogonal", "ldsampler"]),
    ("rfilter", &["box", "tent", "gaussian", "mitchell", "catmullrom", "lanczos"]),
    (
        "integrator",
        &[
            "direct",
            "path",
            "aov",
            "volpath",
            "volpathmis",
            "prb",
            "prb_basic",
            "prbvolpath",
            "direct_projective",
            "prb_projective",
            "moment",
            "stokes",
            "ptracer",
            "depth",
        ],
    ),
    ("texture", &["bitmap", "checkerboard", "mesh_attribute", "volume"]),
    ("bsdf", &["hair", "pplastic", "bumpmap", "principledthindielectric", "retarder", "circular", "measured_polarized", "null"]),
    ("medium", &["homogeneous", "heterogeneous"]),
    ("phase", &["isotropic", "hg", "rayleigh", "blendphase", "tabphase", "sggx"]),
];

/// The class of plugin type `plugin`, if it is a known plugin.
#[must_use]
pub fn plugin_class(plugin: &str) -> Option<&'static str> {
    if PLUGINS.contains(&plugin) {
        return Some("bsdf");
    }
    CLASSES.iter().find(|(_, names)| names.contains(&plugin)).map(|(class, _)| *class)
}

/// Read a scene dictionary (a JSON object with `"type": "scene"`); `source` names it in messages, whose
/// places are JSON paths (`$.ball.bsdf.alpha`).
pub fn load_value(value: &J, source: &str) -> Result<SceneDescription> {
    let J::Object(root) = value else {
        return Err(Error::spec("$", "a scene dictionary must be an object with \"type\": \"scene\""));
    };
    match root.get("type") {
        Some(J::String(t)) if t == "scene" => {}
        Some(J::String(t)) => return Err(Error::spec("$.type", format!("a scene dictionary has \"type\": \"scene\", got \"{t}\""))),
        _ => return Err(Error::spec("$", "a scene dictionary needs \"type\": \"scene\"")),
    }
    let mut ids = HashMap::new();
    for (key, v) in root.iter().filter(|(k, _)| *k != "type") {
        let at = format!("$.{key}");
        let J::Object(map) = v else {
            return Err(Error::spec(at, "every entry of a scene dictionary must be a plugin ({\"type\": …})"));
        };
        let id = match map.get("id") {
            Some(J::String(id)) => id.clone(),
            Some(_) => return Err(Error::spec(format!("{at}.id"), "\"id\" must be a string")),
            None => key.clone(),
        };
        declare(&mut ids, id, v, at.clone())?;
        collect_nested_ids(map, &at, &mut ids)?;
    }
    let scope = DictScope { ids, stack: RefCell::new(Vec::new()), resolved: RefCell::new(HashMap::new()) };
    let mut desc = SceneDescription { source: source.to_string(), ..SceneDescription::default() };
    let mut total = 0;
    for (key, v) in root.iter().filter(|(k, _)| *k != "type") {
        let at = format!("$.{key}");
        if v.get("type").and_then(J::as_str) == Some("ref") {
            return Err(Error::spec(at, "a reference belongs inside a plugin, not at the top level of the scene"));
        }
        let props = Props::from_json_scoped(v, &at, Some(&scope))?;
        total += props.plugin_count();
        if total > MAX_PLUGINS {
            return Err(Error::spec(at, format!("more than {MAX_PLUGINS} plugins in the scene once references are expanded")));
        }
        match props.class() {
            "shape" => desc.shapes.push(props),
            "emitter" => desc.emitters.push(props),
            class @ ("sensor" | "integrator") => {
                let slot = if class == "sensor" { &mut desc.sensor } else { &mut desc.integrator };
                if let Some(prev) = slot {
                    return Err(Error::spec(at, format!("a second {class}; the first is at {}", prev.at())));
                }
                *slot = Some(props);
            }
            // Declared for references; built where they are used.
            "bsdf" | "texture" => {}
            class => return Err(Error::spec(at, format!("a `{class}` belongs inside another plugin, not at the top level of the scene"))),
        }
    }
    Ok(desc)
}

fn declare<'a>(ids: &mut HashMap<String, (&'a J, String)>, id: String, v: &'a J, at: String) -> Result<()> {
    if let Some((_, first)) = ids.get(&id) {
        return Err(Error::spec(at, format!("id \"{id}\" is declared twice (first at {first})")));
    }
    ids.insert(id, (v, at));
    Ok(())
}

/// Nested plugins with an explicit `"id"` can be referred to too.
fn collect_nested_ids<'a>(map: &'a serde_json::Map<String, J>, at: &str, ids: &mut HashMap<String, (&'a J, String)>) -> Result<()> {
    for (key, v) in map {
        if let J::Object(inner) = v {
            let here = format!("{at}.{key}");
            let is_ref = inner.get("type").and_then(J::as_str) == Some("ref");
            if let (Some(J::String(id)), false) = (inner.get("id"), is_ref) {
                declare(ids, id.clone(), v, here.clone())?;
            }
            collect_nested_ids(inner, &here, ids)?;
        }
    }
    Ok(())
}

struct DictScope<'a> {
    ids: HashMap<String, (&'a J, String)>,
    /// References being resolved, to reject cycles.
    stack: RefCell<Vec<String>>,
    /// Each referenced plugin, read once and copied for every further reference.
    resolved: RefCell<HashMap<String, Props>>,
}

impl JsonScope for DictScope<'_> {
    fn class_of(&self, plugin: &str, at: &str) -> Result<&'static str> {
        plugin_class(plugin).ok_or_else(|| Error::spec(at, format!("unknown plugin type `{plugin}`")))
    }

    fn reference(&self, id: &str, at: &str) -> Result<Props> {
        let Some((target, target_at)) = self.ids.get(id) else {
            let mut known: Vec<&str> = self.ids.keys().map(String::as_str).collect();
            known.sort_unstable();
            return Err(Error::spec(at, format!("reference to an unknown id \"{id}\" (ids: {})", known.join(", "))));
        };
        if let Some(props) = self.resolved.borrow().get(id) {
            return Ok(props.clone());
        }
        if self.stack.borrow().iter().any(|s| s == id) {
            return Err(Error::spec(at, format!("reference cycle through id \"{id}\"")));
        }
        if self.stack.borrow().len() >= crate::props::MAX_NESTING {
            return Err(Error::spec(at, format!("references nested more than {} deep", crate::props::MAX_NESTING)));
        }
        self.stack.borrow_mut().push(id.to_string());
        let props = Props::from_json_scoped(target, target_at, Some(self));
        self.stack.borrow_mut().pop();
        if let Ok(p) = &props {
            self.resolved.borrow_mut().insert(id.to_string(), p.clone());
        }
        props
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{mitsuba_xml, Scene};
    use serde_json::json;

    fn err(dict: J) -> String {
        match load_value(&dict, "t").and_then(Scene::build) {
            Ok(_) => panic!("expected an error for {dict}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn every_class_is_named_once() {
        let mut seen = std::collections::HashSet::new();
        for name in CLASSES.iter().flat_map(|(_, n)| n.iter()).chain(PLUGINS.iter()) {
            assert!(seen.insert(*name), "plugin `{name}` is in two classes");
        }
        assert_eq!(plugin_class("roughconductor"), Some("bsdf"));
        assert_eq!(plugin_class("hdrfilm"), Some("film"));
        assert_eq!(plugin_class("nonsense"), None);
    }

    /// The dictionary and the XML form of one scene build the same thing (compared via the Debug text
    /// of the description, which holds every parameter and class).
    #[test]
    fn dict_matches_xml() {
        let xml = r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="3"/></integrator>
            <sensor type="perspective"><float name="fov" value="40"/>
                <transform name="to_world"><matrix value="1 0 0 0.5  0 1 0 0  0 0 1 -4  0 0 0 1"/></transform>
                <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
                <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
            </sensor>
            <bsdf type="roughconductor" id="gold"><float name="alpha" value="0.2"/><string name="material" value="Au"/></bsdf>
            <shape type="sphere"><point name="center" x="0" y="0" z="1"/><ref id="gold"/></shape>
            <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
        </scene>"#;
        let from_xml = Scene::build(mitsuba_xml::load_str(xml, "x.xml", std::path::Path::new("."), &[]).unwrap()).unwrap();
        let dict = json!({
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 3},
            "sensor": {"type": "perspective", "fov": 40,
                "to_world": [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, -4], [0, 0, 0, 1]],
                "film": {"type": "hdrfilm", "width": 16, "height": 12},
                "sampler": {"type": "independent", "sample_count": 4}},
            "gold": {"type": "roughconductor", "alpha": 0.2, "material": "Au"},
            "ball": {"type": "sphere", "center": [0, 0, 1], "bsdf": {"type": "ref", "id": "gold"}},
            "light": {"type": "rectangle", "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [1, 2, 3]}}},
        });
        let from_dict = Scene::build(load_value(&dict, "d").unwrap()).unwrap();
        assert_eq!(format!("{:?}", from_dict.camera), format!("{:?}", from_xml.camera));
        assert_eq!(format!("{:?}", from_dict.shapes), format!("{:?}", from_xml.shapes));
        assert_eq!(format!("{:?}", from_dict.materials), format!("{:?}", from_xml.materials));
        assert_eq!(format!("{:?}", from_dict.lights), format!("{:?}", from_xml.lights));
        assert_eq!((from_dict.film, from_dict.sampler, from_dict.integrator), (from_xml.film, from_xml.sampler, from_xml.integrator));
    }

    /// Instancing as Mitsuba 3's dictionaries write it: a top-level `shapegroup`, and instances that refer
    /// to it by id; the same shapes as the XML form.
    #[test]
    fn instances_refer_to_their_group() {
        let xml = r#"<scene version="3.0.0"><sensor type="perspective"/>
            <shape type="shapegroup" id="g"><shape type="sphere"><float name="radius" value="0.5"/></shape></shape>
            <shape type="instance"><ref id="g"/><transform name="to_world"><translate x="2"/></transform></shape>
            <shape type="instance"><ref id="g"/></shape>
        </scene>"#;
        let from_xml = Scene::build(mitsuba_xml::load_str(xml, "x.xml", std::path::Path::new("."), &[]).unwrap()).unwrap();
        let dict = json!({
            "type": "scene",
            "sensor": {"type": "perspective"},
            "g": {"type": "shapegroup", "ball": {"type": "sphere", "radius": 0.5}},
            "a": {"type": "instance", "group": {"type": "ref", "id": "g"},
                  "to_world": [[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]},
            "b": {"type": "instance", "group": {"type": "ref", "id": "g"}},
        });
        let from_dict = Scene::build(load_value(&dict, "d").unwrap()).unwrap();
        assert_eq!(from_dict.shapes.len(), 2);
        assert_eq!(format!("{:?}", from_dict.shapes), format!("{:?}", from_xml.shapes));
    }

    #[test]
    fn errors_name_the_json_path() {
        let cam = json!({"type": "perspective"});
        for (dict, want) in [
            (json!({"type": "shape"}), "\"type\": \"scene\""),
            (json!({"type": "scene", "s": cam, "b": {"type": "sphere", "radius": -1}}), "$.b.radius"),
            (json!({"type": "scene", "s": cam, "b": {"type": "sphere", "bsdf": {"type": "diffuse", "refl": 0.5}}}), "$.b.bsdf.refl"),
            (json!({"type": "scene", "s": cam, "b": {"type": "sphere", "bsdf": {"type": "ref", "id": "x"}}}), "unknown id \"x\""),
            (json!({"type": "scene", "s": cam, "b": {"type": "teapot"}}), "$.b: unknown plugin type `teapot`"),
            (json!({"type": "scene", "s": cam, "b": {"type": "bsplinecurve"}}), "unsupported shape `bsplinecurve`"),
            (json!({"type": "scene", "s": cam, "f": {"type": "hdrfilm"}}), "belongs inside another plugin"),
            (json!({"type": "scene", "s": cam, "t": cam}), "a second sensor"),
            (json!({"type": "scene", "s": cam, "b": {"type": "sphere", "to_world": [[1, 0], [0, 1]]}}), "4 rows of 4 numbers"),
            (
                json!({"type": "scene", "s": cam, "b": {"type": "sphere", "to_world": [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]]}}),
                "singular",
            ),
            (
                json!({"type": "scene", "s": cam, "a": {"type": "twosided", "bsdf": {"type": "ref", "id": "a"}},
                       "b": {"type": "sphere", "bsdf": {"type": "ref", "id": "a"}}}),
                "reference cycle",
            ),
            (json!({"type": "scene", "b": {"type": "sphere"}}), "no <sensor>"),
        ] {
            let e = err(dict);
            assert!(e.contains(want), "{e} should contain {want}");
        }
    }

    /// A chain of references 1000 long (the readers would recurse once per link) and a chain that doubles
    /// at each link (2⁴⁰ copies) are clear errors, quickly.
    #[test]
    fn hostile_reference_chains_are_errors() {
        let start = std::time::Instant::now();
        let mut chain = serde_json::Map::new();
        chain.insert("type".into(), json!("scene"));
        for i in 0..1000 {
            chain.insert(format!("a{i}"), json!({"type": "twosided", "bsdf": {"type": "ref", "id": format!("a{}", i + 1)}}));
        }
        chain.insert("a1000".into(), json!({"type": "diffuse"}));
        let e = load_value(&J::Object(chain), "d").unwrap_err().to_string();
        assert!(e.contains("references nested more than 64 deep"), "{e}");
        let mut doubling = serde_json::Map::new();
        doubling.insert("type".into(), json!("scene"));
        doubling.insert("b0".into(), json!({"type": "diffuse"}));
        for i in 1..40 {
            let r = json!({"type": "ref", "id": format!("b{}", i - 1)});
            doubling.insert(format!("b{i}"), json!({"type": "blendbsdf", "bsdf_0": r, "bsdf_1": r}));
        }
        let e = load_value(&J::Object(doubling), "d").unwrap_err().to_string();
        assert!(e.contains("more than 262144 plugins"), "{e}");
        // Bounded, not benchmarked (the machine running tests is shared): unbounded, this is 2⁴⁰ plugins.
        assert!(start.elapsed().as_secs_f64() < 20.0, "{:?}", start.elapsed());
    }

    #[test]
    fn references_may_point_forward_and_to_nested_ids() {
        let dict = json!({
            "type": "scene",
            "cam": {"type": "perspective"},
            "a": {"type": "sphere", "bsdf": {"type": "ref", "id": "later"}},
            "b": {"type": "sphere", "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "id": "inner", "reflectance": 0.25}}},
            "c": {"type": "sphere", "bsdf": {"type": "ref", "id": "inner"}},
            "later": {"type": "conductor"},
        });
        let scene = Scene::build(load_value(&dict, "d").unwrap()).unwrap();
        assert_eq!(scene.shapes.len(), 3);
        let names: Vec<&str> = scene
            .materials
            .iter()
            .map(|m| match m {
                crate::scene::Material::Fixed(b) => b.plugin_name(),
                _ => "textured",
            })
            .collect();
        assert_eq!(names, ["conductor", "twosided", "diffuse"]);
    }
}
