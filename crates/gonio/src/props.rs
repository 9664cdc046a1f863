//! Plugin descriptions: the parameters of one Mitsuba-style plugin (`type` plus named values), read from
//! a JSON object in Mitsuba's dictionary form or from an XML element in Mitsuba's scene format.
//!
//! Models read their parameters with typed getters that check ranges; [`Props::finish`] then rejects
//! anything nobody asked for, so a misspelt parameter is an error rather than silently ignored.
//!
//! | JSON value                                  | XML element                          | read as          |
//! |---------------------------------------------|--------------------------------------|------------------|
//! | `0.5`                                       | `<float name=… value="0.5"/>`, `<integer>` | number     |
//! | `true`                                      | `<boolean name=… value="true"/>`     | bool             |
//! | `"Au"`                                      | `<string name=… value="Au"/>`        | string           |
//! | `[0.1, 0.2, 0.3]`, `{"type": "rgb", "value": …}` | `<rgb name=… value="0.1, 0.2, 0.3"/>` | colour (a number is grey) |
//! | `{"type": "spectrum", "value": 0.5}`        | `<spectrum name=… value="0.5"/>`     | number (uniform spectrum; in an emission, the equal-energy one) |
//! | `{"type": "spectrum", "value": [[400, 0.1], [700, 0.3]]}`, `{"type": "spectrum", "filename": "x.spd"}` | `<spectrum name=… value="400:0.1, 700:0.3"/>`, `filename="x.spd"` | its RGB reduction, and the table ([`Props::spectrum`]) |
//! | `{"type": "diffuse", …}` under any key      | nested `<bsdf type="diffuse">`       | nested plugin    |

use crate::error::{Error, Result};
use crate::spectrum::illuminant::Spectrum;
use crate::spectrum::piecewise::PiecewiseLinear;
use crate::spectrum::Rgb;
use crate::xml::{parse_numbers, parse_spectrum, parse_transform, parse_vector, xml_at, XmlEnv, XmlSource};
use std::cell::{Cell, RefCell};
use std::sync::Arc;

/// One parameter value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Number(f64),
    Bool(bool),
    String(String),
    /// A list of numbers (a colour when it has three).
    List(Vec<f64>),
    /// A `<point>` or `<vector>`.
    Vector(glam::Vec3),
    /// A `<transform>`.
    Transform(crate::math::Transform),
    Nested(Props),
}

/// Limits that keep a hostile description from exhausting memory or time (2026-11, issue 8): a plugin
/// tree may hold at most this many plugins once references are expanded (each `<ref>` copies its target,
/// so a chain of plugins that each refer to the previous one twice would otherwise double at every
/// link, the "billion laughs" pattern)...
pub const MAX_PLUGINS: usize = 1 << 18;
/// ...nest at most this deep (the readers recurse once per level)...
pub const MAX_NESTING: usize = 64;
/// ...and one plugin may take at most this many parameters (each new one is compared with those before).
pub const MAX_PARAMETERS: usize = 1024;

impl Value {
    /// A parameter value from JSON, read as in a plugin description (module docs); `at` locates it in
    /// messages. A `{"type": "ref"}` is an error here (it needs a scene).
    ///
    /// # Errors
    /// A value of no kind in the table, or a malformed colour or nested plugin.
    pub fn from_json(v: &serde_json::Value, at: &str) -> Result<Value> {
        json_value(v, at, None)
    }

    fn kind(&self) -> &'static str {
        match self {
            Value::Number(_) => "a number",
            Value::Bool(_) => "a boolean",
            Value::String(_) => "a string",
            Value::List(_) => "a list of numbers",
            Value::Vector(_) => "a point or vector",
            Value::Transform(_) => "a transform",
            Value::Nested(_) => "a nested plugin",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
struct Entry {
    name: String,
    value: Value,
    at: String,
    used: Cell<bool>,
    /// A texture's value at a hit ([`Props::set_texture_value`]): the range-checked readers clamp it into
    /// their range instead of rejecting it.
    clamped: bool,
    /// The spectrum a `<spectrum>` gave (`value` is its RGB reduction), for spectral mode
    /// ([`crate::xml::parse_spectrum`]).
    spectrum: Option<Arc<Spectrum>>,
}

/// The parameters of one plugin.
#[derive(Clone, Debug, PartialEq)]
pub struct Props {
    /// The element the plugin was given as (`bsdf`, `shape`, `emitter`, `texture`, …); empty for JSON.
    class: String,
    plugin: String,
    id: Option<String>,
    at: String,
    entries: Vec<Entry>,
    /// Every name a model asked for, to list the accepted parameters in errors.
    asked: RefCell<Vec<&'static str>>,
    /// Plugins in this tree, itself included (checked against [`MAX_PLUGINS`]).
    plugins: usize,
}

impl Props {
    /// An empty description of plugin `plugin`, located at `at` (for messages).
    #[must_use]
    pub fn new(plugin: &str, at: &str) -> Self {
        Props {
            class: String::new(),
            plugin: plugin.into(),
            id: None,
            at: at.into(),
            entries: Vec::new(),
            asked: RefCell::new(Vec::new()),
            plugins: 1,
        }
    }

    /// Add a parameter (the last of equal names wins, as in Mitsuba's dictionaries).
    pub fn set(&mut self, name: &str, value: Value, at: &str) {
        self.entries.retain(|e| e.name != name);
        self.entries.push(Entry { name: name.into(), value, at: at.into(), used: Cell::new(false), clamped: false, spectrum: None });
        self.plugins = 1 + self.entries.iter().map(|e| if let Value::Nested(p) = &e.value { p.plugins } else { 0 }).sum::<usize>();
    }

    /// [`Props::set`] for values read from a file: refuses a parameter past [`MAX_PARAMETERS`] and a
    /// tree past [`MAX_PLUGINS`] (checked before a nested plugin is stored, so before it is copied further).
    pub(crate) fn set_checked(&mut self, name: &str, value: Value, at: &str) -> Result<()> {
        if self.entries.len() >= MAX_PARAMETERS && !self.has(name) {
            return Err(Error::spec(at, format!("`{}` has more than {MAX_PARAMETERS} parameters", self.plugin)));
        }
        if let Value::Nested(p) = &value {
            if self.plugins + p.plugins > MAX_PLUGINS {
                return Err(Error::spec(
                    at,
                    format!("more than {MAX_PLUGINS} plugins in one tree once references are expanded (a reference copies its target)"),
                ));
            }
        }
        self.set(name, value, at);
        Ok(())
    }

    /// The number of plugins in this tree, itself and every nested (or referenced) plugin included.
    #[must_use]
    pub fn plugin_count(&self) -> usize {
        self.plugins
    }

    #[must_use]
    pub fn plugin_type(&self) -> &str {
        &self.plugin
    }

    /// The kind of plugin (`bsdf`, `shape`, `emitter`, `texture`, `sensor`, …): the XML tag; empty for JSON.
    #[must_use]
    pub fn class(&self) -> &str {
        &self.class
    }

    #[must_use]
    pub fn id(&self) -> Option<&str> {
        self.id.as_deref()
    }

    /// Where this plugin was described: "file:line:col" or a JSON path.
    #[must_use]
    pub fn at(&self) -> &str {
        &self.at
    }

    /// Every parameter as (name, value, where given), in the order given, without marking any as read.
    pub fn values(&self) -> impl Iterator<Item = (&str, &Value, &str)> {
        self.entries.iter().map(|e| (e.name.as_str(), &e.value, e.at.as_str()))
    }

    fn entry(&self, name: &'static str) -> Option<&Entry> {
        self.asked.borrow_mut().push(name);
        let e = self.entries.iter().find(|e| e.name == name)?;
        e.used.set(true);
        Some(e)
    }

    fn wrong(&self, e: &Entry, expected: &str) -> Error {
        Error::spec(&e.at, format!("parameter `{}` of `{}` must be {expected}, got {}", e.name, self.plugin, e.value.kind()))
    }

    /// Whether the parameter was given (does not count as reading it).
    #[must_use]
    pub fn has(&self, name: &str) -> bool {
        self.entries.iter().any(|e| e.name == name)
    }

    /// A finite number in `[lo, hi]`, or `default` when absent.
    pub fn float_in(&self, name: &'static str, default: f32, lo: f32, hi: f32) -> Result<f32> {
        let Some(e) = self.entry(name) else { return Ok(default) };
        let v = match &e.value {
            Value::Number(v) => *v,
            _ => return Err(self.wrong(e, "a number")),
        };
        let v = if e.clamped && v.is_finite() { v.clamp(f64::from(lo), f64::from(hi)) } else { v };
        if !(v >= lo as f64 && v <= hi as f64) {
            return Err(Error::spec(
                &e.at,
                format!("parameter `{name}` of `{}` must be a number in {}, got {v}", self.plugin, range(lo, hi)),
            ));
        }
        Ok(v as f32)
    }

    /// A finite number > 0, or `default` when absent.
    pub fn float_positive(&self, name: &'static str, default: f32) -> Result<f32> {
        let v = self.float_in(name, default, 0.0, f32::MAX)?;
        if v <= 0.0 {
            let at = self.entry(name).map_or(self.at.clone(), |e| e.at.clone());
            return Err(Error::spec(at, format!("parameter `{name}` of `{}` must be a number > 0, got {v}", self.plugin)));
        }
        Ok(v)
    }

    /// A colour with every channel in `[lo, hi]` (a number is a grey), or `default` when absent.
    pub fn rgb_in(&self, name: &'static str, default: Rgb, lo: f32, hi: f32) -> Result<Rgb> {
        let Some(e) = self.entry(name) else { return Ok(default) };
        let c = match &e.value {
            Value::Number(v) => [*v; 3],
            Value::List(l) if l.len() == 3 => [l[0], l[1], l[2]],
            Value::Nested(t) if t.class == "texture" => {
                return Err(Error::spec(
                    &e.at,
                    format!(
                        "textures are not yet supported: parameter `{name}` of `{}` is a `{}` texture; give a colour",
                        self.plugin, t.plugin
                    ),
                ))
            }
            _ => return Err(self.wrong(e, "a colour (a number or three numbers)")),
        };
        // A table whose every value is in range reduces to a colour that may not be (a saturated spectrum
        // is outside the sRGB gamut): clamped into the range, as Mitsuba 3 clamps it.
        let in_gamut = |t: &PiecewiseLinear| t.values().iter().all(|v| (f64::from(lo)..=f64::from(hi)).contains(v));
        let clamp = e.clamped || matches!(e.spectrum.as_deref(), Some(Spectrum::Tabulated(t)) if in_gamut(t));
        let c = if clamp { c.map(|v| if v.is_finite() { v.clamp(f64::from(lo), f64::from(hi)) } else { v }) } else { c };
        if c.iter().any(|v| !(*v >= lo as f64 && *v <= hi as f64)) {
            return Err(Error::spec(
                &e.at,
                format!(
                    "parameter `{name}` of `{}` must have every channel in {}, got [{}, {}, {}]",
                    self.plugin,
                    range(lo, hi),
                    c[0],
                    c[1],
                    c[2]
                ),
            ));
        }
        Ok(Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32))
    }

    /// A reflectance-like colour in [0, 1]³.
    pub fn reflectance(&self, name: &'static str, default: Rgb) -> Result<Rgb> {
        self.rgb_in(name, default, 0.0, 1.0)
    }

    /// A list of numbers: a JSON array, or an XML string of comma- or space-separated numbers.
    pub fn floats(&self, name: &'static str) -> Result<Option<Vec<f64>>> {
        let Some(e) = self.entry(name) else { return Ok(None) };
        let list = match &e.value {
            Value::List(l) => l.clone(),
            Value::Number(v) => vec![*v],
            Value::String(s) => parse_numbers(s).ok_or_else(|| self.wrong(e, "a list of numbers"))?,
            _ => return Err(self.wrong(e, "a list of numbers")),
        };
        if list.iter().any(|v| !v.is_finite()) {
            return Err(Error::spec(&e.at, format!("parameter `{name}` of `{}` must hold finite numbers", self.plugin)));
        }
        Ok(Some(list))
    }

    /// An integer in `[lo, hi]`, or `default` when absent.
    pub fn integer_in(&self, name: &'static str, default: i64, lo: i64, hi: i64) -> Result<i64> {
        let Some(e) = self.entry(name) else { return Ok(default) };
        let v = match &e.value {
            Value::Number(v) if v.fract() == 0.0 => *v,
            _ => return Err(self.wrong(e, "an integer")),
        };
        if !(v >= lo as f64 && v <= hi as f64) {
            return Err(Error::spec(&e.at, format!("parameter `{name}` of `{}` must be an integer in [{lo}, {hi}], got {v}", self.plugin)));
        }
        Ok(v as i64)
    }

    /// A point or vector, or `None` when absent.
    pub fn vector(&self, name: &'static str) -> Result<Option<glam::Vec3>> {
        let Some(e) = self.entry(name) else { return Ok(None) };
        match &e.value {
            Value::Vector(v) => Ok(Some(*v)),
            Value::List(l) if l.len() == 3 => Ok(Some(glam::Vec3::new(l[0] as f32, l[1] as f32, l[2] as f32))),
            _ => Err(self.wrong(e, "a point (x, y, z)")),
        }
    }

    /// A transform, or the identity when absent.
    pub fn transform(&self, name: &'static str) -> Result<crate::math::Transform> {
        let Some(e) = self.entry(name) else { return Ok(crate::math::Transform::IDENTITY) };
        match &e.value {
            Value::Transform(t) => Ok(*t),
            _ => Err(self.wrong(e, "a <transform>")),
        }
    }

    /// A pinhole's field of view as Mitsuba's `perspective` sensor and `projector` emitter read it: `fov`
    /// degrees along `fov_axis` (default `x`), or else `focal_length` (default "50mm", a 35 mm film
    /// equivalent) as a field of view along the diagonal; both given is an error.
    pub fn field_of_view(&self) -> Result<(f32, String)> {
        if self.has("fov") {
            if self.has("focal_length") {
                return Err(Error::spec(self.at_param("focal_length"), "give `fov` or `focal_length`, not both"));
            }
            return Ok((self.float_in("fov", 45.0, 1e-3, 179.999)?, self.string("fov_axis")?.unwrap_or_else(|| "x".into())));
        }
        let raw = self.string("focal_length")?.unwrap_or_else(|| "50mm".into());
        let f: f32 = raw.trim().trim_end_matches("mm").trim().parse().ok().filter(|f: &f32| *f > 0.0).ok_or_else(|| {
            Error::spec(self.at_param("focal_length"), format!("`focal_length` must be a length like \"50mm\", got \"{raw}\""))
        })?;
        let _ = self.string("fov_axis")?;
        Ok(((36.0f32.hypot(24.0) / (2.0 * f)).atan().to_degrees() * 2.0, "diagonal".to_string()))
    }

    /// Where parameter `name` was given, or where the plugin was when it was not.
    #[must_use]
    pub fn at_param(&self, name: &str) -> &str {
        self.entries.iter().find(|e| e.name == name).map_or(&self.at, |e| &e.at)
    }

    /// The nested plugin given as parameter `name` (e.g. a spot light's `texture`), or `None` when absent.
    pub fn plugin(&self, name: &'static str) -> Result<Option<&Props>> {
        let Some(e) = self.entry(name) else { return Ok(None) };
        match &e.value {
            Value::Nested(p) => Ok(Some(p)),
            _ => Err(self.wrong(e, "a nested plugin")),
        }
    }

    /// Nested plugins of one class (`"emitter"`, `"bsdf"`, …), marking them as read.
    #[must_use]
    pub fn nested_of(&self, class: &str) -> Vec<&Props> {
        self.entries
            .iter()
            .filter_map(|e| match &e.value {
                Value::Nested(p) if p.class == class => {
                    e.used.set(true);
                    Some(p)
                }
                _ => None,
            })
            .collect()
    }

    /// A string, or `None` when absent.
    pub fn string(&self, name: &'static str) -> Result<Option<String>> {
        let Some(e) = self.entry(name) else { return Ok(None) };
        match &e.value {
            Value::String(s) => Ok(Some(s.clone())),
            _ => Err(self.wrong(e, "a string")),
        }
    }

    /// A parameter that may be a number or a name (e.g. `int_ior = 1.5` or `"bk7"`).
    pub fn number_or_name(&self, name: &'static str) -> Result<Option<NumberOrName>> {
        let Some(e) = self.entry(name) else { return Ok(None) };
        match &e.value {
            Value::Number(v) => Ok(Some(NumberOrName::Number(*v, e.at.clone()))),
            Value::String(s) => Ok(Some(NumberOrName::Name(s.clone(), e.at.clone()))),
            _ => Err(self.wrong(e, "a number or a name")),
        }
    }

    /// The spectrum parameter `name` was given as, where a `<spectrum>` gave one (its value, as the other
    /// getters read it, is the spectrum's RGB reduction).
    #[must_use]
    pub fn spectrum(&self, name: &str) -> Option<Arc<Spectrum>> {
        self.entries.iter().find(|e| e.name == name).and_then(|e| e.spectrum.clone())
    }

    /// The table parameter `name` was given as (a `<spectrum>` of `λ:value` pairs or an `.spd` file), marking
    /// it read.
    #[must_use]
    pub fn spectrum_table(&self, name: &'static str) -> Option<PiecewiseLinear> {
        let e = self.entry(name)?;
        match e.spectrum.as_deref() {
            Some(Spectrum::Tabulated(table)) => Some(table.clone()),
            _ => None,
        }
    }

    /// A boolean, or `default` when absent.
    pub fn bool(&self, name: &'static str, default: bool) -> Result<bool> {
        let Some(e) = self.entry(name) else { return Ok(default) };
        match &e.value {
            Value::Bool(b) => Ok(*b),
            _ => Err(self.wrong(e, "true or false")),
        }
    }

    /// Nested plugins, in the order they were given, whatever their parameter names.
    #[must_use]
    pub fn nested(&self) -> Vec<&Props> {
        self.nested_named().into_iter().map(|(_, p)| p).collect()
    }

    /// Nested plugins with their parameter names (`_arg_0`, `_arg_1`, … for unnamed XML elements, as
    /// Mitsuba 3 names them), in the order they were given.
    #[must_use]
    pub fn nested_named(&self) -> Vec<(&str, &Props)> {
        self.entries
            .iter()
            .filter_map(|e| match &e.value {
                Value::Nested(p) => {
                    e.used.set(true);
                    Some((e.name.as_str(), p))
                }
                _ => None,
            })
            .collect()
    }

    /// Remove every nested `<texture>` parameter, here and in nested plugins, and return them with their
    /// paths (`["reflectance"]`, `["_arg_0", "reflectance"]` for a texture inside a nested BSDF).
    /// [`Props::set_path`] puts a value back at such a path.
    pub fn take_textures(&mut self) -> Vec<(Vec<String>, Props)> {
        let mut found = Vec::new();
        let mut keep = Vec::with_capacity(self.entries.len());
        for mut e in std::mem::take(&mut self.entries) {
            match &mut e.value {
                Value::Nested(p) if p.class == "texture" => {
                    let Value::Nested(p) = e.value else { unreachable!() };
                    found.push((vec![e.name], p));
                    continue;
                }
                Value::Nested(p) => {
                    for (mut path, t) in p.take_textures() {
                        path.insert(0, e.name.clone());
                        found.push((path, t));
                    }
                }
                _ => {}
            }
            keep.push(e);
        }
        self.entries = keep;
        found
    }

    /// The nested plugin at `path` (names of nested plugins from this one, as [`Props::take_textures`]
    /// gives them; the empty path is this one), without marking anything as read.
    #[must_use]
    pub fn nested_at(&self, path: &[String]) -> Option<&Props> {
        match path {
            [] => Some(self),
            [first, rest @ ..] => match &self.entries.iter().find(|e| &e.name == first)?.value {
                Value::Nested(p) => p.nested_at(rest),
                _ => None,
            },
        }
    }

    /// Set a parameter at a path returned by [`Props::take_textures`]; `at` locates it in messages.
    pub fn set_path(&mut self, path: &[String], value: Value, at: &str) {
        self.put_path(path, value, at, false);
    }

    fn put_path(&mut self, path: &[String], value: Value, at: &str, clamped: bool) {
        match path {
            [] => {}
            [name] => {
                self.set(name, value, at);
                if let Some(e) = self.entries.last_mut() {
                    e.clamped = clamped;
                }
            }
            [first, rest @ ..] => {
                if let Some(Value::Nested(p)) = self.entries.iter_mut().find(|e| &e.name == first).map(|e| &mut e.value) {
                    p.put_path(rest, value, at, clamped);
                }
            }
        }
    }

    /// [`Props::set_path`] for a texture's value at a hit: where a reader checks a range (`float_in`,
    /// `rgb_in`, `reflectance`), a finite value outside it is clamped into it rather than rejected — a
    /// roughness to at least 10⁻⁴ as Mitsuba's microfacet distributions take it, a blend weight into
    /// [0, 1] as Mitsuba's `blendbsdf` clips it, a reflectance per channel into [0, 1] as a textured
    /// `diffuse` always was. A texture's values are only known at the hits, so an error there could only
    /// have been a wrong (black) surface.
    pub fn set_texture_value(&mut self, path: &[String], value: Value, at: &str) {
        self.put_path(path, value, at, true);
    }

    /// Reject parameters that no model asked for.
    pub fn finish(&self) -> Result<()> {
        if let Some(e) = self.entries.iter().find(|e| !e.used.get()) {
            let mut asked = self.asked.borrow().clone();
            asked.sort_unstable();
            asked.dedup();
            let accepted = if asked.is_empty() { "none".to_string() } else { asked.join(", ") };
            return Err(Error::spec(&e.at, format!("unknown parameter `{}` for `{}` (accepted: {accepted})", e.name, self.plugin)));
        }
        Ok(())
    }

    /// Replace every `<ref>` to a plugin declared after it (read with [`XmlEnv::forward_refs`]) by the
    /// plugin `target(id, at)` returns (fully resolved already, so its size is known before it is copied).
    /// A tree past [`MAX_PLUGINS`] is an error at the `<ref>`.
    pub fn resolve_refs(&mut self, target: &mut dyn FnMut(&str, &str) -> Result<Props>) -> Result<()> {
        for i in 0..self.entries.len() {
            let e = &mut self.entries[i];
            let Value::Nested(p) = &mut e.value else { continue };
            if p.class == REF_PLACEHOLDER {
                let id = p.id.clone().unwrap_or_default();
                let found = target(&id, &e.at)?;
                if self.plugins + found.plugins > MAX_PLUGINS {
                    return Err(Error::spec(
                        &e.at,
                        format!("<ref id=\"{id}\">: more than {MAX_PLUGINS} plugins in one tree once references are expanded"),
                    ));
                }
                *p = found;
            } else {
                p.resolve_refs(target)?;
            }
            self.plugins = 1 + self.entries.iter().map(|e| if let Value::Nested(p) = &e.value { p.plugins } else { 0 }).sum::<usize>();
        }
        Ok(())
    }

    /// Whether this tree holds a `<ref>` not resolved yet.
    #[must_use]
    pub fn has_forward_refs(&self) -> bool {
        self.entries.iter().any(|e| matches!(&e.value, Value::Nested(p) if p.class == REF_PLACEHOLDER || p.has_forward_refs()))
    }

    // ---------------------------------------------------------------- JSON

    /// Parse a JSON object in Mitsuba's dictionary form.
    pub fn from_json(text: &str) -> Result<Props> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| Error::Syntax { at: format!("JSON spec:{}:{}", e.line(), e.column()), message: format!("not valid JSON: {e}") })?;
        Props::from_json_value(&value, "$")
    }

    /// Build from an already parsed JSON object; `path` names it in messages (`$` for the root).
    pub fn from_json_value(value: &serde_json::Value, path: &str) -> Result<Props> {
        Props::from_json_scoped(value, path, None)
    }

    /// Build from a JSON object inside a scene dictionary: `scope` names each plugin's class (the XML
    /// tag it would have) and resolves `{"type": "ref", "id": …}`. Without a scope (one model on its own)
    /// classes stay empty and a reference is an error.
    pub(crate) fn from_json_scoped(value: &serde_json::Value, path: &str, scope: Option<&dyn JsonScope>) -> Result<Props> {
        let serde_json::Value::Object(map) = value else {
            return Err(Error::spec(path, "expected a JSON object with a \"type\" key"));
        };
        let Some(serde_json::Value::String(plugin)) = map.get("type") else {
            return Err(Error::spec(path, "expected a \"type\" key naming the plugin, e.g. {\"type\": \"diffuse\"}"));
        };
        let mut props = Props::new(plugin, path);
        if let Some(scope) = scope {
            props.class = scope.class_of(plugin, path)?.to_string();
        }
        for (key, v) in map {
            let at = format!("{path}.{key}");
            match key.as_str() {
                "type" => {}
                "id" => match v {
                    serde_json::Value::String(s) => props.id = Some(s.clone()),
                    _ => return Err(Error::spec(at, "\"id\" must be a string")),
                },
                _ => {
                    if let Some((c, spectrum)) = json_spectrum(key, v, &at)? {
                        props.set_checked(key, colour_value(c), &at)?;
                        if let (Some(spectrum), Some(e)) = (spectrum, props.entries.last_mut()) {
                            e.spectrum = Some(Arc::new(spectrum));
                        }
                        continue;
                    }
                    let value = json_value(v, &at, scope)?;
                    props.set_checked(key, value, &at)?;
                }
            }
        }
        Ok(props)
    }

    /// The description in Mitsuba's dictionary form, which [`Props::from_json`] reads back to the same
    /// parameters: numbers, booleans, strings, lists (colours), points and vectors as three numbers,
    /// transforms as their 4 × 4 row-major matrix, nested plugins as objects with their `type` (and `id`),
    /// tables and uniform emission spectra as `{"type": "spectrum"}`, an emitter's `d65` and `blackbody` as
    /// those plugins.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::{json, Value as J};
        let mut map = serde_json::Map::new();
        map.insert("type".into(), J::String(self.plugin.clone()));
        if let Some(id) = &self.id {
            map.insert("id".into(), J::String(id.clone()));
        }
        for e in &self.entries {
            let v = match (&e.value, e.spectrum.as_deref()) {
                (_, Some(Spectrum::Tabulated(t))) => {
                    json!({"type": "spectrum", "value": t.wavelengths().iter().zip(t.values()).map(|(l, v)| [*l, *v]).collect::<Vec<_>>()})
                }
                (_, Some(Spectrum::Constant(v))) => json!({"type": "spectrum", "value": v}),
                (_, Some(Spectrum::D65 { scale })) => json!({"type": "d65", "scale": scale}),
                (_, Some(Spectrum::Blackbody(b))) => json!({"type": "blackbody", "temperature": b.temperature()}),
                (value, _) => value_json(value),
            };
            map.insert(e.name.clone(), v);
        }
        J::Object(map)
    }

    // ---------------------------------------------------------------- XML

    /// Parse an XML document whose root is a `<bsdf>` element, or whose root holds exactly one.
    pub fn from_xml_bsdf(text: &str, source: &str) -> Result<Props> {
        let doc = crate::xml::parse_document(text, source)?;
        let source = &XmlSource::new(source, text);
        let root = doc.root_element();
        let bsdf = if root.has_tag_name("bsdf") {
            root
        } else {
            let found: Vec<_> = root.children().filter(|n| n.has_tag_name("bsdf")).collect();
            match found.as_slice() {
                [one] => *one,
                [] => {
                    return Err(Error::spec(xml_at(source, root), format!("expected a <bsdf> element, found <{}>", root.tag_name().name())))
                }
                _ => return Err(Error::spec(xml_at(source, root), format!("expected one <bsdf> element, found {}", found.len()))),
            }
        };
        Props::from_xml_element(bsdf, source)
    }

    /// Build from one plugin element (`<bsdf type="…">`) of a Mitsuba XML document, outside a scene
    /// (no parameters, references or search paths).
    pub fn from_xml_element(node: roxmltree::Node, source: &XmlSource) -> Result<Props> {
        Props::from_xml_element_in(node, source, &XmlEnv::default())
    }

    /// Build from one plugin element within a scene: `$name` substituted, `<ref id>` resolved, file
    /// names resolved against the search paths, nested plugins of every kind, points, vectors,
    /// transforms and spectra read.
    pub fn from_xml_element_in(node: roxmltree::Node, source: &XmlSource, env: &XmlEnv) -> Result<Props> {
        Props::from_xml_nested(node, source, env, 1)
    }

    /// [`Props::from_xml_element_in`] for an element `depth` plugins deep.
    fn from_xml_nested(node: roxmltree::Node, source: &XmlSource, env: &XmlEnv, depth: usize) -> Result<Props> {
        let at = xml_at(source, node);
        if depth > MAX_NESTING {
            return Err(Error::spec(at, format!("plugins nested more than {MAX_NESTING} deep")));
        }
        let tag = node.tag_name().name();
        let plugin = env.attr(node, "type", source)?.ok_or_else(|| Error::spec(&at, format!("<{tag}> needs a type attribute")))?;
        let mut props = Props::new(&plugin, &at);
        props.class = tag.to_string();
        props.id = env.attr(node, "id", source)?;
        let mut unnamed = 0;
        for child in node.children().filter(roxmltree::Node::is_element) {
            let cat = xml_at(source, child);
            let ctag = child.tag_name().name();
            let name = env.attr(child, "name", source)?;
            // Mitsuba 3's names for unnamed nested plugins: `_arg_0`, `_arg_1`, … in order (an `aov`
            // integrator's channels carry them, e.g. `_arg_0.R`).
            let mut auto_name = || {
                unnamed += 1;
                format!("_arg_{}", unnamed - 1)
            };
            if PLUGIN_TAGS.contains(&ctag) {
                let nested = Props::from_xml_nested(child, source, env, depth + 1)?;
                let key = name.unwrap_or_else(&mut auto_name);
                props.set_checked(&key, Value::Nested(nested), &cat)?;
                continue;
            }
            if ctag == "ref" {
                let id = env.required(child, "id", source)?;
                let key = name.unwrap_or_else(&mut auto_name);
                let Some(target) = env.refs.get(&id) else {
                    if !env.forward_refs {
                        return Err(Error::spec(&cat, format!("<ref id=\"{id}\">: no plugin with this id was declared before")));
                    }
                    // Declared later in the scene (Mitsuba 3 resolves ids once the whole file is read):
                    // a placeholder that [`Props::resolve_refs`] replaces.
                    let mut placeholder = Props::new(REF_PLACEHOLDER, &cat);
                    placeholder.class = REF_PLACEHOLDER.into();
                    placeholder.id = Some(id);
                    props.set_checked(&key, Value::Nested(placeholder), &cat)?;
                    continue;
                };
                if props.plugins + target.plugins > MAX_PLUGINS {
                    return Err(Error::spec(
                        &cat,
                        format!("<ref id=\"{id}\">: more than {MAX_PLUGINS} plugins in one tree once references are expanded"),
                    ));
                }
                props.set_checked(&key, Value::Nested(target.clone()), &cat)?;
                continue;
            }
            let name = name.ok_or_else(|| Error::spec(&cat, format!("<{ctag}> needs a name attribute")))?;
            let value = match ctag {
                "point" | "vector" => Value::Vector(parse_vector(child, env, source, 0.0)?),
                "transform" => Value::Transform(parse_transform(child, env, source)?),
                "spectrum" => {
                    let (c, spectrum) = parse_spectrum(child, env, source, tag == "emitter")?;
                    props.set_checked(&name, colour_value(c), &cat)?;
                    if let (Some(spectrum), Some(e)) = (spectrum, props.entries.last_mut()) {
                        e.spectrum = Some(Arc::new(spectrum));
                    }
                    continue;
                }
                "float" | "integer" | "boolean" | "string" | "rgb" => {
                    let raw = env
                        .attr(child, "value", source)?
                        .ok_or_else(|| Error::spec(&cat, format!("<{ctag} name=\"{name}\"> needs a value attribute")))?;
                    let bad = |what: &str| Error::spec(&cat, format!("<{ctag} name=\"{name}\">: expected {what}, got \"{raw}\""));
                    match ctag {
                        "float" => Value::Number(parse_number(&raw).ok_or_else(|| bad("a number"))?),
                        "integer" => Value::Number(raw.trim().parse::<i64>().map_err(|_| bad("an integer"))? as f64),
                        // In any case, as Mitsuba 3 reads them (the Blender exporter's tests write "False").
                        "boolean" => Value::Bool(match raw.trim().to_ascii_lowercase().as_str() {
                            "true" => true,
                            "false" => false,
                            _ => return Err(bad("true or false")),
                        }),
                        "string" if name == "filename" && !env.search_paths.is_empty() => {
                            Value::String(env.resolve_file(&raw, &cat)?.to_string_lossy().into_owned())
                        }
                        "string" => Value::String(raw.clone()),
                        _ => match parse_numbers(&raw).as_deref() {
                            Some([v]) => Value::Number(*v),
                            Some([r, g, b]) => Value::List(vec![*r, *g, *b]),
                            _ => return Err(bad("one or three numbers")),
                        },
                    }
                }
                _ => return Err(Error::spec(&cat, format!("unsupported element <{ctag}> inside <{tag} type=\"{plugin}\">"))),
            };
            props.set_checked(&name, value, &cat)?;
        }
        Ok(props)
    }
}

/// The class and type of a `<ref>` to a plugin not declared yet (see [`Props::resolve_refs`]).
const REF_PLACEHOLDER: &str = "ref";

/// Elements that describe a plugin (and may nest).
const PLUGIN_TAGS: &[&str] =
    &["bsdf", "emitter", "texture", "shape", "sensor", "film", "sampler", "rfilter", "integrator", "medium", "phase", "volume"];

/// A parameter given as a number or a name (e.g. an index of refraction).
#[derive(Clone, Debug, PartialEq)]
pub enum NumberOrName {
    /// The number and where it was given.
    Number(f64, String),
    /// The name and where it was given.
    Name(String, String),
}

fn range(lo: f32, hi: f32) -> String {
    if hi == f32::MAX {
        format!("[{lo}, ∞)")
    } else {
        format!("[{lo}, {hi}]")
    }
}

fn parse_number(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok()
}

/// What a scene dictionary adds to a plugin's JSON: the class of each plugin type (Mitsuba knows it from
/// its plugin registry; the XML format spells it as the tag) and the targets of references.
pub(crate) trait JsonScope {
    /// The class (`"bsdf"`, `"shape"`, `"emitter"`, …) of plugin type `plugin`, given at `at`.
    fn class_of(&self, plugin: &str, at: &str) -> Result<&'static str>;
    /// The plugin declared with id `id`, for a `{"type": "ref", "id": …}` at `at`.
    fn reference(&self, id: &str, at: &str) -> Result<Props>;
}

/// A 4×4 matrix given as four rows of four numbers (a nested list, e.g. a numpy array's `tolist()`),
/// read as a transform like the XML `<matrix value="…16 numbers, row-major…"/>`.
fn json_matrix(rows: &[serde_json::Value], at: &str) -> Result<Value> {
    let bad = || Error::spec(at, "a matrix must be 4 rows of 4 numbers (row-major, as numpy prints it)");
    if rows.len() != 4 {
        return Err(bad());
    }
    let mut m = [0.0f64; 16];
    for (r, row) in rows.iter().enumerate() {
        let row = row.as_array().filter(|row| row.len() == 4).ok_or_else(bad)?;
        for (c, v) in row.iter().enumerate() {
            m[4 * r + c] = v.as_f64().ok_or_else(bad)?;
        }
    }
    let t = crate::math::Transform::from_rows(&m).ok_or_else(|| Error::spec(at, "the matrix is singular or not finite"))?;
    // Composed onto the identity as the XML loader composes its operations, so that a dictionary and the
    // equivalent XML give the same bits (products with the identity turn −0 into +0).
    Ok(Value::Transform(t.then_after(crate::math::Transform::IDENTITY)))
}

/// A value in Mitsuba's dictionary form (see [`Props::to_json`]).
fn value_json(value: &Value) -> serde_json::Value {
    use serde_json::{json, Value as J};
    match value {
        Value::Number(x) => json!(x),
        Value::Bool(b) => J::Bool(*b),
        Value::String(s) => J::String(s.clone()),
        Value::List(l) => json!(l),
        Value::Vector(v) => json!([v.x, v.y, v.z]),
        Value::Transform(t) => J::Array(t.matrix.transpose().to_cols_array_2d().iter().map(|row| json!(row)).collect()),
        Value::Nested(p) => p.to_json(),
    }
}

/// A colour as a parameter value: a number where it is grey, else three numbers.
fn colour_value(c: Rgb) -> Value {
    if c.r() == c.g() && c.g() == c.b() {
        Value::Number(f64::from(c.r()))
    } else {
        Value::List(c.to_f64().to_vec())
    }
}

/// The parameters that hold an emitter's emission: a spectrum given to them is radiance (an emitter's
/// `<spectrum>` in XML), reduced without an illuminant, and a uniform one is the equal-energy spectrum.
pub const EMISSION: [&str; 3] = ["radiance", "intensity", "irradiance"];

/// Parameter `name`'s `{"type": "spectrum"}` given as a table — `"value"` a list of [λ nm, value] pairs,
/// or `"filename"` an `.spd` file — or, for an emission ([`EMISSION`]), as a number, or a spectrum plugin
/// (`{"type": "d65", "scale": …}`, `{"type": "blackbody", "temperature": …}`, `{"type": "uniform", "value":
/// …}`): its RGB reduction and spectrum, as the XML `<spectrum>` gives them
/// ([`crate::xml::tabulated_spectrum`], [`crate::xml::spectrum_of_plugin`]). `None` for any other value (a
/// colour's number, read by [`json_value`]).
fn json_spectrum(name: &str, v: &serde_json::Value, at: &str) -> Result<Option<(Rgb, Option<Spectrum>)>> {
    use serde_json::Value as J;
    let J::Object(map) = v else { return Ok(None) };
    let emission = EMISSION.contains(&name);
    let kind = map.get("type").and_then(J::as_str).unwrap_or_default();
    if let Some(accepted) = crate::xml::spectrum_plugin_parameters(kind) {
        // A spectrum plugin, {"type": "d65", "scale": 2}, {"type": "blackbody", "temperature": 5000} or
        // {"type": "uniform", "value": 0.5}: the XML <spectrum type=…>'s.
        let mut parameters = Vec::new();
        for (key, value) in map.iter().filter(|(k, _)| *k != "type") {
            let number = value.as_f64().filter(|v| v.is_finite());
            match number {
                Some(x) if accepted.contains(&key.as_str()) => parameters.push((key.clone(), x)),
                _ => {
                    return Err(Error::spec(
                        at,
                        format!("`{key}` in a `{kind}` spectrum: it takes a number for each of: {}", accepted.join(", ")),
                    ))
                }
            }
        }
        return crate::xml::spectrum_of_plugin(kind, &parameters, emission)
            .map(Some)
            .map_err(|e| Error::spec(at, format!("`{kind}` spectrum: {e}")));
    }
    if kind != "spectrum" {
        return Ok(None);
    }
    if let Some(extra) = map.keys().find(|k| !matches!(k.as_str(), "type" | "value" | "filename")) {
        return Err(Error::spec(at, format!("unknown key `{extra}` in a spectrum (it takes \"value\" or \"filename\")")));
    }
    let table = |w, v| crate::xml::tabulated_spectrum(w, v, emission).map_err(|e| Error::spec(at, format!("spectrum: {e}")));
    match (map.get("value"), map.get("filename")) {
        (Some(_), Some(_)) => Err(Error::spec(at, "a spectrum takes \"value\" or \"filename\", not both")),
        (None, Some(J::String(file))) => {
            let path = std::path::PathBuf::from(file);
            let text = std::fs::read_to_string(&path).map_err(|source| Error::Io { path: path.clone(), source })?;
            let (w, v) = crate::spectrum::named::parse_spd(&text).map_err(|e| Error::spec(at, format!("{}: {e}", path.display())))?;
            table(w, v).map(Some)
        }
        (None, _) => Err(Error::spec(at, "a spectrum needs \"value\" (a number or [λ, value] pairs) or \"filename\" (an .spd file)")),
        (Some(J::Number(n)), None) if emission => Ok(Some(crate::xml::uniform_spectrum(n.as_f64().unwrap_or(f64::NAN), true))),
        (Some(J::Array(pairs)), None) if pairs.first().is_some_and(J::is_array) => {
            let bad = || Error::spec(at, "a spectrum's \"value\" pairs must be [wavelength nm, value], two numbers each");
            let (mut w, mut v) = (Vec::with_capacity(pairs.len()), Vec::with_capacity(pairs.len()));
            for pair in pairs {
                match pair.as_array().map(Vec::as_slice) {
                    Some([l, x]) => {
                        w.push(l.as_f64().ok_or_else(bad)?);
                        v.push(x.as_f64().ok_or_else(bad)?);
                    }
                    _ => return Err(bad()),
                }
            }
            table(w, v).map(Some)
        }
        _ => Ok(None),
    }
}

fn json_value(v: &serde_json::Value, at: &str, scope: Option<&dyn JsonScope>) -> Result<Value> {
    use serde_json::Value as J;
    Ok(match v {
        J::Array(items) if items.first().is_some_and(J::is_array) => json_matrix(items, at)?,
        J::Number(n) => Value::Number(n.as_f64().ok_or_else(|| Error::spec(at, "number out of range"))?),
        J::Bool(b) => Value::Bool(*b),
        J::String(s) => Value::String(s.clone()),
        J::Array(items) => Value::List(
            items.iter().map(|i| i.as_f64().ok_or_else(|| Error::spec(at, "expected a list of numbers"))).collect::<Result<_>>()?,
        ),
        J::Object(map) => match map.get("type").and_then(J::as_str) {
            Some("rgb") | Some("spectrum") => {
                let inner = map.get("value").ok_or_else(|| Error::spec(at, "expected a \"value\" key"))?;
                if let Some(extra) = map.keys().find(|k| *k != "type" && *k != "value") {
                    return Err(Error::spec(at, format!("unknown key `{extra}` in a colour")));
                }
                match json_value(inner, &format!("{at}.value"), None)? {
                    v @ Value::Number(_) => v,
                    Value::List(l) if l.len() == 3 && map["type"] == "rgb" => Value::List(l),
                    _ => return Err(Error::spec(at, "a colour's \"value\" must be a number or three numbers")),
                }
            }
            Some("ref") => {
                let Some(scope) = scope else {
                    return Err(Error::spec(at, "a {\"type\": \"ref\"} can only refer to another plugin of a scene dictionary"));
                };
                let id = match (map.get("id"), map.len()) {
                    (Some(J::String(id)), 2) => id,
                    _ => return Err(Error::spec(at, "a reference is {\"type\": \"ref\", \"id\": \"<id of a plugin>\"}")),
                };
                Value::Nested(scope.reference(id, at)?)
            }
            Some(_) => Value::Nested(Props::from_json_scoped(v, at, scope)?),
            None => return Err(Error::spec(at, "a nested object needs a \"type\" key")),
        },
        J::Null => return Err(Error::spec(at, "null is not a parameter value")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dictionary_spectra_are_the_xml_ones() {
        // A table in a dictionary is the XML <spectrum>'s: the same RGB reduction and the same table, and
        // it survives the round trip through `to_json`; a uniform emission is the equal-energy spectrum.
        let xml = Props::from_xml_bsdf(
            r#"<bsdf type="diffuse"><spectrum name="reflectance" value="400:0.2, 500:0.7, 700:0.9"/></bsdf>"#,
            "t.xml",
        )
        .unwrap();
        let dict =
            Props::from_json(r#"{"type": "diffuse", "reflectance": {"type": "spectrum", "value": [[400, 0.2], [500, 0.7], [700, 0.9]]}}"#)
                .unwrap();
        assert_eq!(dict.rgb_in("reflectance", Rgb::ZERO, 0.0, 1.0).unwrap(), xml.rgb_in("reflectance", Rgb::ZERO, 0.0, 1.0).unwrap());
        assert_eq!(dict.spectrum_table("reflectance"), xml.spectrum_table("reflectance"));
        assert!(dict.spectrum_table("reflectance").is_some());
        let back = Props::from_json(&dict.to_json().to_string()).unwrap();
        assert_eq!(back.spectrum_table("reflectance"), xml.spectrum_table("reflectance"));
        let light = Props::from_json(r#"{"type": "area", "radiance": {"type": "spectrum", "value": 2}}"#).unwrap();
        let c = light.rgb_in("radiance", Rgb::ZERO, 0.0, f32::MAX).unwrap();
        assert!((c.r() / 2.0 - 1.2049).abs() < 1e-3 && (c.b() / 2.0 - 0.9093).abs() < 1e-3, "{c:?}");
        assert!(matches!(light.spectrum("radiance").as_deref(), Some(Spectrum::Constant(v)) if *v == 2.0));
        // The spectrum plugins, as the XML <spectrum type=…> reads them, and back through `to_json`.
        for (json, xml) in [
            (r#"{"type": "d65", "scale": 2.5}"#, r#"<spectrum name="radiance" type="d65"><float name="scale" value="2.5"/></spectrum>"#),
            (
                r#"{"type": "blackbody", "temperature": 4000}"#,
                r#"<spectrum name="radiance" type="blackbody"><float name="temperature" value="4000"/></spectrum>"#,
            ),
            (
                r#"{"type": "uniform", "value": 3}"#,
                r#"<spectrum name="radiance" type="uniform"><float name="value" value="3"/></spectrum>"#,
            ),
        ] {
            let dict = Props::from_json(&format!(r#"{{"type": "area", "radiance": {json}}}"#)).unwrap();
            let xml = Props::from_xml_element(
                roxmltree::Document::parse(&format!(r#"<emitter type="area">{xml}</emitter>"#)).unwrap().root_element(),
                &XmlSource::new("t.xml", ""),
            )
            .unwrap();
            let rgb = |p: &Props| p.rgb_in("radiance", Rgb::ZERO, 0.0, f32::MAX).unwrap();
            assert_eq!(rgb(&dict), rgb(&xml), "{json}");
            assert_eq!(dict.spectrum("radiance"), xml.spectrum("radiance"), "{json}");
            let back = Props::from_json(&dict.to_json().to_string()).unwrap();
            assert_eq!((rgb(&back), back.spectrum("radiance")), (rgb(&dict), dict.spectrum("radiance")), "{json}");
        }
        let d65 = Props::from_json(r#"{"type": "area", "radiance": {"type": "d65", "scale": 2}}"#).unwrap();
        assert_eq!(d65.rgb_in("radiance", Rgb::ZERO, 0.0, f32::MAX).unwrap(), Rgb::splat(2.0));
        for (json, expect) in [
            (r#"{"type": "blackbody"}"#, "$.radiance: `blackbody` spectrum: needs a `temperature` (K)"),
            (r#"{"type": "blackbody", "temperature": -5}"#, "temperature > 0 K"),
            (r#"{"type": "d65", "scale": "2"}"#, "`scale` in a `d65` spectrum: it takes a number for each of: scale"),
            (r#"{"type": "d65", "temperature": 5000}"#, "`temperature` in a `d65` spectrum"),
            (r#"{"type": "uniform"}"#, "$.radiance: `uniform` spectrum: needs a `value`"),
        ] {
            let e = Props::from_json(&format!(r#"{{"type": "area", "radiance": {json}}}"#)).unwrap_err().to_string();
            assert!(e.contains(expect), "{json}: {e}");
        }
        let e =
            Props::from_json(r#"{"type": "diffuse", "reflectance": {"type": "blackbody", "temperature": 5000}}"#).unwrap_err().to_string();
        assert!(e.contains("an emitter's spectrum"), "{e}");
        let grey = Props::from_json(r#"{"type": "diffuse", "reflectance": {"type": "spectrum", "value": 0.3}}"#).unwrap();
        assert_eq!(grey.rgb_in("reflectance", Rgb::ZERO, 0.0, 1.0).unwrap(), Rgb::splat(0.3));
        for (json, expect) in [
            (r#"{"type": "spectrum", "value": [[400, 0.2], [400, 0.3]]}"#, "$.reflectance: spectrum: line 2"),
            (r#"{"type": "spectrum", "value": [[400, 0.2, 1], [500, 0.3]]}"#, "two numbers each"),
            (r#"{"type": "spectrum", "value": [[400, 0.2]]}"#, "at least two points"),
            (r#"{"type": "spectrum", "filename": "/nonexistent/x.spd"}"#, "/nonexistent/x.spd"),
            (r#"{"type": "spectrum", "value": 1, "filename": "x.spd"}"#, "not both"),
            (r#"{"type": "spectrum", "values": 1}"#, "unknown key `values`"),
        ] {
            let e = Props::from_json(&format!(r#"{{"type": "diffuse", "reflectance": {json}}}"#)).unwrap_err().to_string();
            assert!(e.contains(expect), "{json}: {e}");
        }
    }

    #[test]
    fn xml_descriptions_read_back_from_their_json() {
        let xml = r#"<bsdf type="twosided" id="coat"><bsdf type="roughplastic"><float name="alpha" value="0.3"/>
            <rgb name="diffuse_reflectance" value="0.2, 0.4, 0.6"/><boolean name="nonlinear" value="true"/>
            <string name="distribution" value="ggx"/><texture type="checkerboard" name="specular_reflectance">
            <transform name="to_uv"><scale x="4" y="2"/><translate x="0.5"/></transform></texture></bsdf></bsdf>"#;
        let p = Props::from_xml_bsdf(xml, "t.xml").unwrap();
        let json = p.to_json();
        assert_eq!(json["type"], "twosided");
        assert_eq!(json["id"], "coat");
        let inner = json.as_object().unwrap().values().find(|v| v.is_object()).unwrap();
        assert_eq!(
            (inner["alpha"].as_f64(), inner["nonlinear"].as_bool(), inner["distribution"].as_str()),
            (Some(0.3), Some(true), Some("ggx"))
        );
        let back = Props::from_json(&json.to_string()).unwrap();
        // The same parameters with the same values (places differ: a JSON path instead of file:line:col).
        let values = |p: &Props| p.to_json().to_string();
        assert_eq!(values(&back), values(&p));
        let texture = &inner["specular_reflectance"];
        assert_eq!(
            (&texture["to_uv"][0], &texture["to_uv"][1]),
            (&serde_json::json!([4.0, 0.0, 0.0, 0.5]), &serde_json::json!([0.0, 2.0, 0.0, 0.0]))
        );
    }

    #[test]
    fn json_values_of_every_kind() {
        let p = Props::from_json(
            r#"{"type": "x", "a": 0.5, "b": [0.1, 0.2, 0.3], "c": {"type": "rgb", "value": 0.25},
            "d": "Au", "e": true, "n": {"type": "diffuse"}}"#,
        )
        .unwrap();
        assert_eq!(p.plugin_type(), "x");
        assert_eq!(p.float_in("a", 0.0, 0.0, 1.0).unwrap(), 0.5);
        assert_eq!(p.reflectance("b", Rgb::ZERO).unwrap(), Rgb::new(0.1, 0.2, 0.3));
        assert_eq!(p.reflectance("c", Rgb::ZERO).unwrap(), Rgb::splat(0.25));
        assert_eq!(p.string("d").unwrap().as_deref(), Some("Au"));
        assert!(p.bool("e", false).unwrap());
        assert_eq!(p.nested().len(), 1);
        p.finish().unwrap();
    }

    #[test]
    fn unknown_parameter_is_named_with_accepted_list() {
        let p = Props::from_json(r#"{"type": "diffuse", "reflectanse": 0.5}"#).unwrap();
        let _ = p.reflectance("reflectance", Rgb::splat(0.5)).unwrap();
        let err = p.finish().unwrap_err().to_string();
        assert!(err.contains("unknown parameter `reflectanse`") && err.contains("accepted: reflectance"), "{err}");
        assert!(err.starts_with("$.reflectanse"), "{err}");
    }

    #[test]
    fn range_errors_name_parameter_and_range() {
        let p = Props::from_json(r#"{"type": "diffuse", "reflectance": [0.5, 1.5, 0.2]}"#).unwrap();
        let err = p.reflectance("reflectance", Rgb::ZERO).unwrap_err().to_string();
        assert!(err.contains("`reflectance`") && err.contains("[0, 1]") && err.contains("1.5"), "{err}");
    }

    #[test]
    fn xml_element_with_line_numbers() {
        let xml = "<bsdf type=\"twosided\">\n  <bsdf type=\"diffuse\">\n    <rgb name=\"reflectance\" value=\"0.1, 0.2, 0.3\"/>\n  </bsdf>\n</bsdf>";
        let p = Props::from_xml_bsdf(xml, "m.xml").unwrap();
        let inner = p.nested()[0];
        assert_eq!(inner.reflectance("reflectance", Rgb::ZERO).unwrap(), Rgb::new(0.1, 0.2, 0.3));
        assert_eq!(inner.at(), "m.xml:2:3");
        let bad = Props::from_xml_bsdf("<bsdf type=\"diffuse\">\n<float name=\"x\" value=\"abc\"/></bsdf>", "m.xml").unwrap_err();
        assert!(bad.to_string().starts_with("m.xml:2:1"), "{bad}");
    }

    /// Booleans in any case, as Mitsuba reads them; anything else is an error.
    #[test]
    fn xml_booleans_ignore_case() {
        for (text, want) in [("True", true), ("FALSE", false), ("false", false)] {
            let p = Props::from_xml_bsdf(&format!("<bsdf type=\"plastic\"><boolean name=\"nonlinear\" value=\"{text}\"/></bsdf>"), "m.xml")
                .unwrap();
            assert_eq!(p.bool("nonlinear", !want).unwrap(), want, "{text}");
        }
        assert!(Props::from_xml_bsdf("<bsdf type=\"plastic\"><boolean name=\"nonlinear\" value=\"yes\"/></bsdf>", "m.xml").is_err());
    }

    #[test]
    fn malformed_input_is_a_syntax_error() {
        assert!(matches!(Props::from_json("{\"type\": "), Err(Error::Syntax { .. })));
        assert!(matches!(Props::from_xml_bsdf("<bsdf", "f.xml"), Err(Error::Syntax { .. })));
        assert!(Props::from_json("[1, 2]").is_err());
        assert!(Props::from_json("{\"reflectance\": 1}").unwrap_err().to_string().contains("\"type\""));
    }
}
