//! Parameter sweeps of lit spheres: one material description rendered once per point of a grid over its
//! top-level parameters (`alpha` × `material`, …). The one place a sweep is expanded, checked, named and
//! rendered: `gonio preview --grid`, `gonio.preview(spec, grid=…)` and `gonio.distributed.preview` (one Ray
//! task per point) all go through [`Sweep`], so a point renders the same image wherever it is rendered.
//!
//! Points run in row-major order over the axes: the first axis varies slowest, the last fastest, and a
//! contact sheet has one column per value of the last axis ([`Sweep::columns`]).
//!
//! ```
//! use gonio::preview::{GridAxis, Sweep};
//! use gonio::props::{Props, Value};
//! let spec = Props::from_json(r#"{"type": "roughconductor"}"#).unwrap();
//! let grid = GridAxis::from_json(r#"[["alpha", [0.05, 0.3]], ["material", ["Au", "Cu"]]]"#).unwrap();
//! let sweep = Sweep::new(spec, grid).unwrap();
//! assert_eq!((sweep.len(), sweep.columns()), (4, 2));
//! assert_eq!(sweep.label(1), "alpha=0.05, material=Cu");
//! assert_eq!(sweep.indices(2), vec![1, 0]);
//! sweep.check().unwrap();
//! ```

use super::{render_preview, Lighting, PreviewImage};
use crate::error::{Error, Result};
use crate::props::{Props, Value};
use crate::scene::spectral::{check_bsdf, Mode};
use crate::scene::Material;
use std::sync::atomic::AtomicBool;

/// Most points one sweep may have (a contact sheet of 64 × 64 spheres): a guard against a grid whose
/// product of lengths was not meant (2026-12, issue 32).
pub const MAX_POINTS: usize = 4096;

/// One axis of a sweep: a top-level parameter and the values it takes.
#[derive(Clone, Debug, PartialEq)]
pub struct GridAxis {
    pub name: String,
    pub values: Vec<Value>,
}

fn grid_error(message: String) -> Error {
    Error::Spec { at: "grid".into(), message }
}

impl GridAxis {
    /// The command line's `NAME=V1,V2,…` (`gonio preview --grid`): each value a number, `true`/`false`, or
    /// else a string (a material or distribution name).
    ///
    /// # Errors
    /// Without `=`, or with an empty value.
    pub fn parse(arg: &str) -> Result<GridAxis> {
        let (name, values) = arg.split_once('=').ok_or_else(|| grid_error(format!("expected NAME=V1,V2,..., got `{arg}`")))?;
        let values = values
            .split(',')
            .map(|v| match v.trim() {
                "" => Err(grid_error(format!("`{arg}` has an empty value"))),
                "true" => Ok(Value::Bool(true)),
                "false" => Ok(Value::Bool(false)),
                v => Ok(v.parse::<f64>().map_or_else(|_| Value::String(v.to_string()), Value::Number)),
            })
            .collect::<Result<_>>()?;
        Ok(GridAxis { name: name.trim().to_string(), values })
    }

    /// Axes from JSON: a list of `[name, [value, …]]` pairs (a list, so that the axes keep their order),
    /// each value as in a JSON plugin description (a number, string, boolean, colour list, `{"type": "rgb",
    /// …}`, a nested plugin).
    ///
    /// # Errors
    /// When the text is not such a list; the message names the parameter and what was expected.
    pub fn from_json(text: &str) -> Result<Vec<GridAxis>> {
        use serde_json::Value as J;
        let json: J =
            serde_json::from_str(text).map_err(|e| Error::Syntax { at: "grid".into(), message: format!("not valid JSON: {e}") })?;
        let J::Array(pairs) = json else {
            return Err(grid_error(format!("expected a list of [name, values] pairs, got {}", json_kind(&json))));
        };
        pairs
            .iter()
            .map(|pair| {
                let (name, values) = match pair.as_array().map(Vec::as_slice) {
                    Some([J::String(name), values]) => (name, values),
                    _ => return Err(grid_error(format!("expected a [name, values] pair, got {pair}"))),
                };
                let J::Array(items) = values else {
                    return Err(grid_error(format!(
                        "parameter `{name}`: expected a list of values (one sphere each), got {} {values}",
                        json_kind(values)
                    )));
                };
                let values =
                    items.iter().enumerate().map(|(i, v)| Value::from_json(v, &format!("grid {name}[{i}]"))).collect::<Result<_>>()?;
                Ok(GridAxis { name: name.clone(), values })
            })
            .collect()
    }

    /// The axis as JSON, the `[name, [value, …]]` pair [`GridAxis::from_json`] reads (numbers, booleans and
    /// strings: what [`GridAxis::parse`] gives).
    #[must_use]
    pub fn to_json(&self) -> String {
        let values: Vec<serde_json::Value> = self
            .values
            .iter()
            .map(|v| match v {
                Value::Number(x) => serde_json::Number::from_f64(*x).map_or(serde_json::Value::Null, serde_json::Value::Number),
                Value::Bool(b) => serde_json::Value::Bool(*b),
                other => serde_json::Value::String(show(other)),
            })
            .collect();
        serde_json::json!([self.name, values]).to_string()
    }
}

fn json_kind(v: &serde_json::Value) -> &'static str {
    use serde_json::Value as J;
    match v {
        J::Null => "null",
        J::Bool(_) => "a boolean",
        J::Number(_) => "a number",
        J::String(_) => "a string",
        J::Array(_) => "a list",
        J::Object(_) => "an object",
    }
}

/// A value as a grid label shows it: `0.05`, `Au`, `true`, `[0.2, 0.5, 0.8]`, a nested plugin's type.
fn show(v: &Value) -> String {
    match v {
        Value::Number(x) => format!("{x}"),
        Value::Bool(b) => format!("{b}"),
        Value::String(s) => s.clone(),
        Value::List(l) => format!("[{}]", l.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ")),
        Value::Vector(v) => format!("{v}"),
        Value::Transform(_) => "transform".into(),
        Value::Nested(p) => p.plugin_type().to_string(),
    }
}

/// A material description and the grid it is swept over.
#[derive(Clone, Debug)]
pub struct Sweep {
    spec: Props,
    axes: Vec<GridAxis>,
}

impl Sweep {
    /// A sweep of `spec` over `axes` (none: the one sphere of `spec` itself). Checks the grid's shape; the
    /// materials are built by [`Sweep::check`] (which reads any measured file once per point).
    ///
    /// # Errors
    /// An axis named empty, nested (`a.b`), `type` or `id`, or twice; an axis without values; more than
    /// [`MAX_POINTS`] points. The message names the parameter.
    pub fn new(spec: Props, axes: Vec<GridAxis>) -> Result<Sweep> {
        for (i, axis) in axes.iter().enumerate() {
            let name = &axis.name;
            if name.is_empty() || name.contains('.') || name == "type" || name == "id" {
                return Err(grid_error(format!(
                    "`{name}` is not a parameter a grid can vary: expected a top-level parameter of `{}` (not `type`, `id` or a nested name)",
                    spec.plugin_type()
                )));
            }
            if axes[..i].iter().any(|a| &a.name == name) {
                return Err(grid_error(format!("parameter `{name}` is given twice")));
            }
            if axis.values.is_empty() {
                return Err(grid_error(format!("parameter `{name}`: expected at least one value, got an empty list")));
            }
        }
        let points = axes.iter().try_fold(1usize, |n, a| n.checked_mul(a.values.len()).filter(|&n| n <= MAX_POINTS));
        if points.is_none() {
            let lengths: Vec<String> = axes.iter().map(|a| format!("{} ({})", a.name, a.values.len())).collect();
            return Err(grid_error(format!("more than {MAX_POINTS} points: {}", lengths.join(" × "))));
        }
        Ok(Sweep { spec, axes })
    }

    /// The number of points (spheres).
    #[must_use]
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// Never: a sweep has at least one point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Columns of a contact sheet: the number of values of the last axis (1 without a grid).
    #[must_use]
    pub fn columns(&self) -> usize {
        self.axes.last().map_or(1, |a| a.values.len())
    }

    #[must_use]
    pub fn axes(&self) -> &[GridAxis] {
        &self.axes
    }

    /// The index into each axis's values of point `point` (row-major: the last axis varies fastest).
    #[must_use]
    pub fn indices(&self, point: usize) -> Vec<usize> {
        debug_assert!(point < self.len(), "point {point} of a sweep of {}", self.len());
        let mut rest = point;
        let mut out = vec![0; self.axes.len()];
        for (slot, axis) in out.iter_mut().zip(&self.axes).rev() {
            *slot = rest % axis.values.len();
            rest /= axis.values.len();
        }
        out
    }

    /// `alpha=0.05, material=Au`: the point's values (empty without a grid).
    #[must_use]
    pub fn label(&self, point: usize) -> String {
        let parts: Vec<String> =
            self.axes.iter().zip(self.indices(point)).map(|(a, i)| format!("{}={}", a.name, show(&a.values[i]))).collect();
        parts.join(", ")
    }

    /// The description of point `point`: the spec with the point's values set (a parameter the spec had is
    /// replaced). Errors in a value are located at `grid NAME=VALUE`.
    #[must_use]
    pub fn props(&self, point: usize) -> Props {
        let mut p = self.spec.clone();
        for (axis, i) in self.axes.iter().zip(self.indices(point)) {
            let value = &axis.values[i];
            p.set(&axis.name, value.clone(), &format!("grid {}={}", axis.name, show(value)));
        }
        p
    }

    /// The material of point `point`.
    ///
    /// # Errors
    /// When the point's description does not build. An error located at a grid value names it (`grid
    /// alpha=-1: …`); any other error of a point of a grid is prefixed with the point (`grid point
    /// material=Xx: $: unknown conductor material …`: a model may locate an error at the plugin).
    pub fn material(&self, point: usize) -> Result<Material> {
        Material::from_props(&self.props(point)).map_err(|e| match e {
            Error::Spec { at, message } if !self.axes.is_empty() && !at.starts_with("grid ") => {
                Error::Spec { at: format!("grid point {}: {at}", self.label(point)), message }
            }
            other => other,
        })
    }

    /// Build every point's material, so that every error shows before the first render.
    ///
    /// # Errors
    /// The first point that does not build.
    pub fn check(&self) -> Result<()> {
        (0..self.len()).try_for_each(|i| self.material(i).map(drop))
    }

    /// Render point `point` as [`render_preview`] does, in `mode`.
    ///
    /// # Errors
    /// Those of [`Sweep::material`] and [`render_preview`]; in spectral mode, a material it does not take
    /// yet ([`check_bsdf`]).
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        point: usize,
        lighting: &Lighting,
        size: u32,
        spp: u32,
        seed: u64,
        mode: Mode,
        cancel: &AtomicBool,
    ) -> Result<PreviewImage> {
        if point >= self.len() {
            return Err(grid_error(format!("point {point} of a sweep of {} points", self.len())));
        }
        let spectral = match mode {
            Mode::Rgb => None,
            Mode::Spectral => Some(check_bsdf(&self.props(point))?),
        };
        render_preview(&|| self.material(point), lighting, size, spp, seed, spectral, cancel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conductor() -> Props {
        Props::from_json(r#"{"type": "roughconductor", "alpha": 0.2}"#).unwrap()
    }

    #[test]
    fn points_are_row_major_and_set_their_values() {
        let axes = vec![GridAxis::parse("alpha=0.05,0.1,0.3").unwrap(), GridAxis::parse("material=Au,Cu").unwrap()];
        let sweep = Sweep::new(conductor(), axes).unwrap();
        assert_eq!((sweep.len(), sweep.columns()), (6, 2));
        assert_eq!(sweep.indices(3), vec![1, 1]);
        assert_eq!(sweep.label(3), "alpha=0.1, material=Cu");
        let p = sweep.props(5);
        assert_eq!(p.float_in("alpha", 0.0, 0.0, 1.0).unwrap(), 0.3);
        assert_eq!(p.string("material").unwrap().as_deref(), Some("Cu"));
        sweep.check().unwrap();
        let one = Sweep::new(conductor(), Vec::new()).unwrap();
        assert_eq!((one.len(), one.columns(), one.label(0)), (1, 1, String::new()));
    }

    #[test]
    fn the_command_line_and_json_forms_agree() {
        let parsed = GridAxis::parse("alpha=0.05, 0.3").unwrap();
        let json = GridAxis::from_json(&format!("[{}]", parsed.to_json())).unwrap();
        assert_eq!(json, vec![parsed]);
        let flags = GridAxis::parse("nonlinear=true,false").unwrap();
        assert_eq!(flags.values, vec![Value::Bool(true), Value::Bool(false)]);
    }

    #[test]
    fn bad_grids_name_the_parameter_and_what_was_expected() {
        let msg = |r: Result<Vec<GridAxis>>| r.unwrap_err().to_string();
        assert!(msg(GridAxis::from_json(r#"[["alpha", 0.1]]"#)).contains("parameter `alpha`: expected a list of values"));
        assert!(msg(GridAxis::from_json(r#"{"alpha": [0.1]}"#)).contains("expected a list of [name, values] pairs"));
        assert!(GridAxis::parse("alpha").is_err() && GridAxis::parse("alpha=0.1,,0.2").is_err());
        let new = |text: &str| Sweep::new(conductor(), GridAxis::from_json(text).unwrap()).unwrap_err().to_string();
        assert!(new(r#"[["alpha", []]]"#).contains("parameter `alpha`: expected at least one value"));
        assert!(new(r#"[["type", ["diffuse"]]]"#).contains("`type` is not a parameter a grid can vary"));
        assert!(new(r#"[["alpha", [0.1]], ["alpha", [0.2]]]"#).contains("`alpha` is given twice"));
        let big = format!(r#"[["alpha", {0:?}], ["eta", {0:?}], ["k", {0:?}]]"#, vec![0.1; 20]);
        assert!(new(&big).contains("more than 4096 points"));
        // A value the model refuses, and a parameter it does not have, are located at the grid value.
        let check = |text: &str| Sweep::new(conductor(), GridAxis::from_json(text).unwrap()).unwrap().check().unwrap_err().to_string();
        let e = check(r#"[["alpha", [0.1, -1]]]"#);
        assert!(e.starts_with("grid alpha=-1:") && e.contains("alpha"), "{e}");
        let e = check(r#"[["alhpa", [0.1]]]"#);
        assert!(e.starts_with("grid alhpa=0.1: unknown parameter `alhpa`"), "{e}");
        let e = check(r#"[["alpha", [0.1]], ["material", ["Au", "Xx"]]]"#);
        assert!(e.starts_with("grid point alpha=0.1, material=Xx: $: ") && e.contains("`Xx`"), "{e}");
    }
}
