//! Each model's parameters, read from the one table that documents them: the table that opens the model's
//! file (STYLE.md: "its module doc opens with a parameter table (name, type, default, meaning)"). The docs,
//! this list and the explorer's form all come from that text; the models' `from_props` give the errors.
//!
//! The `type` column is read as:
//!
//! | text                         | [`Kind`]                                  |
//! |------------------------------|-------------------------------------------|
//! | `float [a, b]`, `float (a, b)` | `Float` with its range (open or closed ends) |
//! | `int [a, b]`                 | `Int` with its range                       |
//! | `rgb [a, b]`, `rgb ≥ 0`      | `Rgb` with its range                       |
//! | `` `a` \| `b` ``             | `Enum` of those names                      |
//! | `float or name`              | `Ior` (a number or a named index)          |
//! | `bool`, `string`, `list of floats` | `Bool`, `String` (`File` for `filename`), `List` |
//! | anything naming `bsdf`       | `Nested` (edited as JSON)                 |
//!
//! Numbers may be written `1e-4`, `10⁵` or with a minus sign `−`.

use crate::bsdf::PLUGINS;
use serde_json::{json, Value};

/// What kind of value a parameter takes.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    Float { range: Option<Range> },
    Int { range: Option<Range> },
    Rgb { range: Range },
    Enum(Vec<String>),
    Ior,
    Bool,
    String,
    File,
    List,
    Nested,
}

/// A range of values: `[min, max]`, either end open (excluded) or absent (unbounded).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub min_open: bool,
    pub max_open: bool,
}

/// One row of a model's parameter table.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// The parameter names of the row (`alpha_u`, `alpha_v` share one row); empty for nested models.
    pub names: Vec<String>,
    pub kind: Kind,
    /// The default as a JSON value where the table gives one that is a value (not "preset", "`alpha`").
    pub default: Option<Value>,
    /// The default as written in the table.
    pub default_text: String,
    pub meaning: String,
}

/// The model files, by plugin name: the text their tables are read from (a test checks that every
/// plugin in [`PLUGINS`] is here).
const SOURCES: &[(&str, &str)] = &[
    ("diffuse", include_str!("../bsdf/diffuse.rs")),
    ("conductor", include_str!("../bsdf/conductor.rs")),
    ("roughconductor", include_str!("../bsdf/rough_conductor.rs")),
    ("torrance_sparrow", include_str!("../bsdf/torrance_sparrow.rs")),
    ("dielectric", include_str!("../bsdf/dielectric.rs")),
    ("roughdielectric", include_str!("../bsdf/rough_dielectric.rs")),
    ("plastic", include_str!("../bsdf/plastic.rs")),
    ("roughplastic", include_str!("../bsdf/rough_plastic.rs")),
    ("thindielectric", include_str!("../bsdf/thin_dielectric.rs")),
    ("blendbsdf", include_str!("../bsdf/blend.rs")),
    ("sum", include_str!("../bsdf/sum.rs")),
    ("twosided", include_str!("../bsdf/twosided.rs")),
    ("mask", include_str!("../bsdf/mask.rs")),
    ("phong", include_str!("../bsdf/phong.rs")),
    ("blinn_phong", include_str!("../bsdf/blinn_phong.rs")),
    ("oren_nayar", include_str!("../bsdf/oren_nayar.rs")),
    ("measured", include_str!("../bsdf/measured.rs")),
    ("layered", include_str!("../bsdf/layered.rs")),
    ("ashikhmin_shirley", include_str!("../bsdf/ashikhmin_shirley.rs")),
    ("merl", include_str!("../bsdf/merl.rs")),
    ("principled", include_str!("../bsdf/principled.rs")),
    ("polarizer", include_str!("../bsdf/polarizer.rs")),
    ("normalmap", include_str!("../bsdf/normal_map.rs")),
];

fn source(plugin: &str) -> Option<&'static str> {
    SOURCES.iter().find(|(p, _)| *p == plugin).map(|(_, s)| *s)
}

/// The first sentence of a model's module doc (its one-line description).
#[must_use]
pub fn about(plugin: &str) -> String {
    let Some(text) = source(plugin) else { return String::new() };
    let mut out = String::new();
    for line in text.lines().map_while(|l| l.strip_prefix("//!")) {
        let line = line.trim();
        if line.is_empty() {
            break;
        }
        out.push_str(if out.is_empty() { "" } else { " " });
        out.push_str(line);
    }
    out
}

/// The parameters of `plugin`, in the order of its table (`None` for an unknown plugin).
#[must_use]
pub fn parameters(plugin: &str) -> Option<Vec<Param>> {
    let text = source(plugin)?;
    let mut rows = text
        .lines()
        .map_while(|l| l.strip_prefix("//!"))
        .map(str::trim)
        .skip_while(|l| !(l.starts_with('|') && l.contains("parameter")))
        .skip(2) // the header and the |---| line
        .take_while(|l| l.starts_with('|'));
    let mut out = Vec::new();
    for row in rows.by_ref() {
        if let Some(p) = parse_row(row) {
            out.push(p);
        }
    }
    Some(out)
}

/// A table row `| names | type | default | meaning |`; `\|` inside a cell is a literal bar.
fn parse_row(row: &str) -> Option<Param> {
    const BAR: &str = "\u{1}";
    let row = row.replace("\\|", BAR);
    let cells: Vec<&str> = row.trim().trim_matches('|').split('|').collect();
    if cells.len() < 4 {
        return None;
    }
    let restore = |s: &str| s.replace(BAR, "|").trim().to_string();
    let names: Vec<String> = backticked(cells[0]);
    let type_text = restore(cells[1]);
    let default_text = restore(cells[2]);
    let meaning = restore(&cells[3..].join("|"));
    let kind = parse_kind(&type_text, names.first().map(String::as_str));
    let default = parse_default(&default_text, &kind);
    Some(Param { names, kind, default, default_text, meaning })
}

/// The `backticked` words of a cell, in order.
fn backticked(cell: &str) -> Vec<String> {
    cell.split('`').skip(1).step_by(2).map(str::to_string).collect()
}

fn parse_kind(text: &str, first_name: Option<&str>) -> Kind {
    let lower = text.to_lowercase();
    if lower.contains("bsdf") || first_name.is_none() {
        return Kind::Nested;
    }
    if text.contains('`') {
        return Kind::Enum(backticked(text));
    }
    if lower.starts_with("float or name") {
        return Kind::Ior;
    }
    if lower.starts_with("float") {
        return Kind::Float { range: parse_range(&lower) };
    }
    if lower.starts_with("int") {
        return Kind::Int { range: parse_range(&lower) };
    }
    if lower.starts_with("rgb") {
        let range = parse_range(&lower).unwrap_or(Range { min: None, max: None, min_open: false, max_open: false });
        return Kind::Rgb { range };
    }
    if lower.starts_with("bool") {
        return Kind::Bool;
    }
    if lower.starts_with("list") {
        return Kind::List;
    }
    if first_name == Some("filename") {
        return Kind::File;
    }
    Kind::String
}

/// `[a, b]`, `(a, b)` (or mixed) anywhere in `text`, or `≥ a`.
fn parse_range(text: &str) -> Option<Range> {
    if let Some(start) = text.find(['[', '(']) {
        let rest = &text[start + 1..];
        if let Some(end) = rest.find([']', ')']) {
            let (lo, hi) = rest[..end].split_once(',')?;
            let (min, max) = (parse_number(lo), parse_number(hi));
            if min.is_some() && max.is_some() {
                return Some(Range { min, max, min_open: text[start..].starts_with('('), max_open: rest[end..].starts_with(')') });
            }
        }
    }
    let at_least = text.split_once('≥')?.1;
    let min = parse_number(at_least.split_whitespace().next()?)?;
    Some(Range { min: Some(min), max: None, min_open: false, max_open: false })
}

/// A number as the tables write it: `0.5`, `1e-4`, `10⁵`, `−1`.
fn parse_number(text: &str) -> Option<f64> {
    let text = text.trim().replace('−', "-");
    if let Ok(v) = text.parse::<f64>() {
        return Some(v);
    }
    // `10⁵`: a base followed by superscript digits.
    const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let split = text.find(|c| SUPERSCRIPTS.contains(&c))?;
    let base: f64 = text[..split].parse().ok()?;
    let mut exponent = 0i32;
    for c in text[split..].chars() {
        exponent = exponent * 10 + SUPERSCRIPTS.iter().position(|&s| s == c)? as i32;
    }
    Some(base.powi(exponent))
}

/// The default as a value: the first word of the cell (`0.1 (e ≈ 198)` → 0.1, `` `"beckmann"` `` →
/// "beckmann"); none for words that name another parameter or a preset.
fn parse_default(text: &str, kind: &Kind) -> Option<Value> {
    let first = text.split_whitespace().next()?.trim_matches(['`', '"']);
    match kind {
        Kind::Float { .. } | Kind::Int { .. } => parse_number(first).map(|v| json!(v)),
        Kind::Rgb { .. } => parse_number(first).map(|v| json!(v)),
        Kind::Bool => match first {
            "true" => Some(json!(true)),
            "false" => Some(json!(false)),
            _ => None,
        },
        Kind::Enum(choices) => choices.iter().find(|c| *c == first).map(|c| json!(c)),
        Kind::Ior => Some(parse_number(first).map_or_else(|| json!(first), |v| json!(v))),
        Kind::String => (first != "—" && first != "preset").then(|| json!(first)),
        Kind::File | Kind::List | Kind::Nested => None,
    }
}

impl Range {
    fn to_json(self) -> Value {
        json!({"min": self.min, "max": self.max, "min_open": self.min_open, "max_open": self.max_open})
    }
}

impl Param {
    /// The row as the explorer's form reads it.
    #[must_use]
    pub fn to_json(&self) -> Value {
        let (kind, range, choices) = match &self.kind {
            Kind::Float { range } => ("float", range.map(Range::to_json), None),
            Kind::Int { range } => ("int", range.map(Range::to_json), None),
            Kind::Rgb { range } => ("rgb", Some(range.to_json()), None),
            Kind::Enum(c) => ("enum", None, Some(c.clone())),
            Kind::Ior => ("ior", None, None),
            Kind::Bool => ("bool", None, None),
            Kind::String => ("string", None, None),
            Kind::File => ("file", None, None),
            Kind::List => ("list", None, None),
            Kind::Nested => ("nested", None, None),
        };
        json!({
            "names": self.names,
            "kind": kind,
            "range": range,
            "choices": choices,
            "default": self.default,
            "default_text": self.default_text,
            "meaning": self.meaning,
        })
    }
}

/// Every plugin with its description and parameter table, as JSON.
#[must_use]
pub fn models_json() -> Value {
    Value::Array(
        PLUGINS
            .iter()
            .map(|&p| {
                let params: Vec<Value> = parameters(p).unwrap_or_default().iter().map(Param::to_json).collect();
                json!({"plugin": p, "about": about(p), "params": params})
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn every_plugin_has_a_table() {
        for &p in PLUGINS {
            let params = parameters(p).unwrap_or_else(|| panic!("{p}: no source in SOURCES"));
            assert!(!params.is_empty(), "{p}: no parameter table");
            assert!(!about(p).is_empty(), "{p}: no description");
        }
    }

    #[test]
    fn rough_conductor_table_reads_as_written() {
        let params = parameters("roughconductor").unwrap();
        let find = |n: &str| params.iter().find(|p| p.names.iter().any(|m| m == n)).unwrap();
        let alpha = find("alpha");
        assert_eq!(alpha.kind, Kind::Float { range: Some(Range { min: Some(1e-4), max: Some(10.0), min_open: false, max_open: false }) });
        assert_eq!(alpha.default, Some(json!(0.1)));
        assert_eq!(find("alpha_v").names, ["alpha_u", "alpha_v"]);
        assert_eq!(find("alpha_v").default, None);
        assert_eq!(find("distribution").kind, Kind::Enum(vec!["beckmann".into(), "ggx".into()]));
        assert_eq!(find("distribution").default, Some(json!("beckmann")));
        assert_eq!(find("sample_visible").kind, Kind::Bool);
        assert_eq!(find("sample_visible").default, Some(json!(true)));
        assert!(matches!(find("eta").kind, Kind::Rgb { range: Range { min: Some(0.0), max: None, .. } }));
        assert!(matches!(find("material").kind, Kind::String));
    }

    #[test]
    fn other_notations() {
        let g = parameters("layered").unwrap().into_iter().find(|p| p.names == ["g"]).unwrap();
        assert_eq!(g.kind, Kind::Float { range: Some(Range { min: Some(-1.0), max: Some(1.0), min_open: true, max_open: true }) });
        let e = parameters("phong").unwrap().into_iter().find(|p| p.names == ["exponent"]).unwrap();
        assert!(matches!(e.kind, Kind::Float { range: Some(Range { max: Some(m), .. }) } if m == 1e5));
        let n = parameters("phong").unwrap().into_iter().find(|p| p.names == ["normalization"]).unwrap();
        assert_eq!(n.kind, Kind::Enum(vec!["none".into(), "energy".into()]));
        assert_eq!(n.default, Some(json!("energy")));
        let f = parameters("merl").unwrap();
        assert_eq!(f[0].kind, Kind::File);
        assert!(f.iter().any(|p| p.kind == Kind::Nested));
        assert_eq!(parameters("no_such"), None);
    }

    /// The tables agree with the code: every model builds from its table's defaults; at each end of each
    /// closed range it is not refused as out of range (another rule may still refuse it: `eta` = 0 with
    /// `k` = 0 is no conductor); a value past a closed end is an error that names the parameter.
    #[test]
    fn tables_agree_with_the_models() {
        for &plugin in PLUGINS {
            let needs_more = parameters(plugin).unwrap().iter().any(|p| matches!(p.kind, Kind::Nested | Kind::File));
            if needs_more {
                continue;
            }
            for p in parameters(plugin).unwrap() {
                let name = &p.names[0];
                let build = |v: Value| Bsdf::from_json(&json!({"type": plugin, name.as_str(): v}).to_string());
                if let Some(d) = &p.default {
                    build(d.clone()).unwrap_or_else(|e| panic!("{plugin}.{name} = default {d}: {e}"));
                }
                let range = match p.kind {
                    Kind::Float { range: Some(r) } | Kind::Int { range: Some(r) } | Kind::Rgb { range: r } => r,
                    _ => continue,
                };
                for (end, open, outside) in [(range.min, range.min_open, -1.0), (range.max, range.max_open, 1.0)] {
                    let Some(end) = end else { continue };
                    if !open {
                        if let Err(e) = build(json!(end)) {
                            let e = e.to_string();
                            assert!(!e.contains(&format!("parameter `{name}`")), "{plugin}.{name} = {end} is in its table's range: {e}");
                        }
                    }
                    let past = end + outside * (0.5 * end.abs()).max(1.0);
                    let e = build(json!(past)).expect_err(&format!("{plugin}.{name} = {past} builds")).to_string();
                    assert!(e.contains(name.as_str()), "{plugin}.{name} = {past}: {e}");
                }
            }
        }
    }
}
