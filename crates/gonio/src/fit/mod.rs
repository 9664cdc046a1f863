//! Fitting analytic models to a measured (or any) BRDF: `gonio fit`.
//!
//! # The error metric (Ngan, Durand & Matusik 2005, "Experimental Analysis of BRDF Models", EGSR, §4)
//! E(p) = √( Σₖ wₖ Σ_c (f_c(ωo,k, ωi,k) cos θi,k − f̂_c(p; ωo,k, ωi,k) cos θi,k)² / Σₖ wₖ ),
//! the cosine-weighted L2 distance between the measured f and the model f̂ with parameters p, summed
//! over the three channels c and over a fixed set of direction pairs k with weights wₖ proportional to
//! the solid-angle measure dωo dωi each pair stands for; as in the paper, pairs with θo or θi above 80°
//! are left out (grazing measurements are the least reliable).
//!
//! The pairs are a fixed stratified set in MERL's half/difference parameterisation (xθh, θd, φd and φh,
//! with the square-root warp of θh, so that the specular peak gets many pairs); since
//! dωo dωi = 4 cos θd sin θh sin θd dθh dφh dθd dφd (Rusinkiewicz 1998) and dθh ∝ xθh dxθh,
//! wₖ ∝ cos θd sin θh sin θd xθh. The measured BRDF is only asked for f at these pairs, so any [`Bsdf`]
//! can be the target: a MERL table, an RGL file, an analytic or layered model.
//!
//! # Optimisation
//! Levenberg–Marquardt ([`lm`]) on the residual vector √(wₖ/Σw)(f − f̂) cos θi, from several starting
//! points (every combination of the per-parameter starts); the best minimum wins. Parameters are
//! optimised through a smooth map from ℝ onto their range (logistic, or logistic in log p for
//! roughness and exponents), so the box constraints always hold.
//!
//! # Models
//! [`MODELS`]: one entry per model; adding a model is one entry (its parameters and its spec).

pub mod lm;

use crate::bsdf::rough_plastic::{TableScope, TableSource};
use crate::bsdf::{Bsdf, BsdfModel};
use crate::error::{Error, Result};
use crate::math::Vec3;
use crate::measured::merl_file::directions_at;
use serde_json::{json, Value};

/// One free parameter: its name, range, whether it is optimised in log space, and its starting values.
#[derive(Clone, Copy, Debug)]
pub struct Param {
    pub name: &'static str,
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
    pub starts: &'static [f64],
}

const fn param(name: &'static str, lo: f64, hi: f64, log: bool, starts: &'static [f64]) -> Param {
    Param { name, lo, hi, log, starts }
}

const ALPHA: Param = param("alpha", 1e-3, 1.5, true, &[0.03, 0.15, 0.5]);
const ETA: [Param; 3] =
    [param("eta.r", 0.05, 6.0, true, &[1.5]), param("eta.g", 0.05, 6.0, true, &[1.5]), param("eta.b", 0.05, 6.0, true, &[1.5])];
const K: [Param; 3] =
    [param("k.r", 1e-3, 12.0, true, &[2.0]), param("k.g", 1e-3, 12.0, true, &[2.0]), param("k.b", 1e-3, 12.0, true, &[2.0])];
const KD: [Param; 3] =
    [param("kd.r", 0.0, 1.0, false, &[0.2]), param("kd.g", 0.0, 1.0, false, &[0.2]), param("kd.b", 0.0, 1.0, false, &[0.2])];
const KS: [Param; 3] =
    [param("ks.r", 0.0, 1.0, false, &[0.3]), param("ks.g", 0.0, 1.0, false, &[0.3]), param("ks.b", 0.0, 1.0, false, &[0.3])];
const EXPONENT: Param = param("exponent", 1.0, 1e5, true, &[10.0, 100.0, 1000.0]);
const RD: [Param; 3] =
    [param("rd.r", 0.0, 1.0, false, &[0.2]), param("rd.g", 0.0, 1.0, false, &[0.2]), param("rd.b", 0.0, 1.0, false, &[0.2])];
const RS: [Param; 3] =
    [param("rs.r", 0.0, 1.0, false, &[0.1]), param("rs.g", 0.0, 1.0, false, &[0.1]), param("rs.b", 0.0, 1.0, false, &[0.1])];

/// A fittable model: its parameters and the spec they make.
#[derive(Debug)]
pub struct FitModel {
    pub name: &'static str,
    pub about: &'static str,
    pub params: &'static [Param],
    pub spec: fn(&[f64]) -> Value,
}

fn rgb(p: &[f64]) -> Value {
    json!([p[0], p[1], p[2]])
}

fn conductor(kind: &str, p: &[f64]) -> Value {
    json!({"type": "roughconductor", "distribution": kind, "alpha": p[0], "eta": rgb(&p[1..4]), "k": rgb(&p[4..7])})
}

fn with_diffuse(glossy: Value, kd: &[f64]) -> Value {
    json!({"type": "sum", "weights": [1.0, 1.0], "diffuse": {"type": "diffuse", "reflectance": rgb(kd)}, "glossy": glossy})
}

const CONDUCTOR: &[Param] = &[ALPHA, ETA[0], ETA[1], ETA[2], K[0], K[1], K[2]];
const CONDUCTOR_DIFFUSE: &[Param] = &[ALPHA, ETA[0], ETA[1], ETA[2], K[0], K[1], K[2], KD[0], KD[1], KD[2]];

/// Every model `gonio fit --model` knows. One entry each.
pub const MODELS: &[FitModel] = &[
    FitModel { name: "ggx", about: "roughconductor, GGX, free α, η, k", params: CONDUCTOR, spec: |p| conductor("ggx", p) },
    FitModel { name: "beckmann", about: "roughconductor, Beckmann, free α, η, k", params: CONDUCTOR, spec: |p| conductor("beckmann", p) },
    FitModel {
        name: "ggx+diffuse",
        about: "Lambertian plus a GGX roughconductor (sum)",
        params: CONDUCTOR_DIFFUSE,
        spec: |p| with_diffuse(conductor("ggx", p), &p[7..10]),
    },
    FitModel {
        name: "beckmann+diffuse",
        about: "Lambertian plus a Beckmann roughconductor (sum)",
        params: CONDUCTOR_DIFFUSE,
        spec: |p| with_diffuse(conductor("beckmann", p), &p[7..10]),
    },
    FitModel {
        name: "roughplastic",
        about: "roughplastic, GGX, free α and diffuse reflectance (int_ior 1.49)",
        params: &[ALPHA, KD[0], KD[1], KD[2]],
        spec: |p| json!({"type": "roughplastic", "distribution": "ggx", "alpha": p[0], "diffuse_reflectance": rgb(&p[1..4])}),
    },
    FitModel {
        name: "torrance_sparrow",
        about: "torrance_sparrow: Blinn D, V-cavity G, free α, η, k",
        params: CONDUCTOR,
        spec: |p| json!({"type": "torrance_sparrow", "alpha": p[0], "eta": rgb(&p[1..4]), "k": rgb(&p[4..7])}),
    },
    FitModel {
        name: "torrance_sparrow+diffuse",
        about: "Lambertian plus torrance_sparrow (sum)",
        params: CONDUCTOR_DIFFUSE,
        spec: |p| with_diffuse(json!({"type": "torrance_sparrow", "alpha": p[0], "eta": rgb(&p[1..4]), "k": rgb(&p[4..7])}), &p[7..10]),
    },
    FitModel {
        name: "blinn_phong",
        about: "blinn_phong (energy-normalised): k_d, k_s, exponent",
        params: &[EXPONENT, KD[0], KD[1], KD[2], KS[0], KS[1], KS[2]],
        spec: |p| json!({"type": "blinn_phong", "exponent": p[0], "diffuse_reflectance": rgb(&p[1..4]), "specular_reflectance": rgb(&p[4..7])}),
    },
    FitModel {
        name: "ashikhmin_shirley",
        about: "ashikhmin_shirley, isotropic (nu = nv = exponent): exponent, R_d, R_s",
        // Isotropic: MERL tables are, and the metric's pairs hold one half-vector azimuth per (θh, θd,
        // φd), which cannot tell nu from nv.
        params: &[EXPONENT, RD[0], RD[1], RD[2], RS[0], RS[1], RS[2]],
        spec: |p| json!({"type": "ashikhmin_shirley", "nu": p[0], "nv": p[0], "rd": rgb(&p[1..4]), "rs": rgb(&p[4..7])}),
    },
];

/// The model called `name`.
pub fn model(name: &str) -> Result<&'static FitModel> {
    MODELS.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = MODELS.iter().map(|m| m.name).collect();
        Error::spec("--model", format!("unknown model `{name}`; expected one of: {}", names.join(", ")))
    })
}

/// A direction pair of the metric, its weight (normalised to sum 1) and the measured f cos θi.
#[derive(Clone, Debug)]
pub struct Pair {
    pub wo: Vec3,
    pub wi: Vec3,
    pub weight: f64,
    pub target: [f64; 3],
}

/// The fixed direction set: `n` strata per axis of (xθh, θd, φd) and 4 values of φh (see the module docs).
pub fn pairs(target: &Bsdf, n: usize) -> Vec<Pair> {
    let max_angle = 80f64.to_radians().cos();
    let mut out = Vec::new();
    for a in 0..n {
        for b in 0..n {
            for c in 0..2 * n {
                let x_h = 90.0 * (a as f64 + 0.5) / n as f64;
                let x_d = 90.0 * (b as f64 + 0.5) / n as f64;
                let x_p = 180.0 * (c as f64 + 0.5) / (2 * n) as f64;
                let (wo, wi) = directions_at(x_h, x_d, x_p);
                if wo.z < max_angle || wi.z < max_angle {
                    continue;
                }
                let theta_h = std::f64::consts::FRAC_PI_2 * (x_h / 90.0).powi(2);
                let theta_d = std::f64::consts::FRAC_PI_2 * x_d / 90.0;
                let weight = theta_d.cos() * theta_h.sin() * theta_d.sin() * x_h;
                // φh only rotates an isotropic BRDF; one rotation keeps ωo off the x axis.
                let rot = |v: glam::DVec3| glam::DVec3::new(0.8 * v.x - 0.6 * v.y, 0.6 * v.x + 0.8 * v.y, v.z).as_vec3().normalize();
                let (wo, wi) = (rot(wo), rot(wi));
                let f = target.f(wo, wi);
                let cos = f64::from(wi.z);
                out.push(Pair { wo, wi, weight, target: [f64::from(f.r()) * cos, f64::from(f.g()) * cos, f64::from(f.b()) * cos] });
            }
        }
    }
    let total: f64 = out.iter().map(|p| p.weight).sum();
    for p in &mut out {
        p.weight /= total;
    }
    out
}

fn to_param(p: &Param, x: f64) -> f64 {
    let s = 1.0 / (1.0 + (-x).exp());
    if p.log {
        (p.lo.ln() + (p.hi.ln() - p.lo.ln()) * s).exp()
    } else {
        p.lo + (p.hi - p.lo) * s
    }
}

fn from_param(p: &Param, v: f64) -> f64 {
    let s = if p.log { (v.ln() - p.lo.ln()) / (p.hi.ln() - p.lo.ln()) } else { (v - p.lo) / (p.hi - p.lo) };
    let s = s.clamp(1e-6, 1.0 - 1e-6);
    (s / (1.0 - s)).ln()
}

/// The result of [`fit`].
#[derive(Clone, Debug)]
pub struct Fit {
    pub model: &'static str,
    pub values: Vec<(&'static str, f64)>,
    pub spec: Value,
    /// E(p) of the module docs.
    pub error: f64,
    /// E(p) relative to √(Σ w |f cos|² / Σ w): the fraction of the signal not explained.
    pub relative_error: f64,
    /// Per θi band of 10° (0–80°): (band start in degrees, RMS error / RMS signal in the band).
    pub per_angle: Vec<(f64, f64)>,
}

/// Evaluate a model spec at the pairs: residuals √w (f cos − f̂ cos) per channel.
fn residuals_of(spec: &Value, pairs: &[Pair], out: &mut [f64]) -> bool {
    let Ok(model) = Bsdf::from_json(&spec.to_string()) else { return false };
    for (k, p) in pairs.iter().enumerate() {
        let f = model.f(p.wo, p.wi);
        let cos = f64::from(p.wi.z);
        let sw = p.weight.sqrt();
        for c in 0..3 {
            out[3 * k + c] = sw * (p.target[c] - f64::from(f.0[c]) * cos);
        }
    }
    true
}

/// Fit `model` to `target` over `pairs` (see the module docs).
pub fn fit(model: &'static FitModel, pairs: &[Pair]) -> Result<Fit> {
    // roughplastic's coating tables from the α grid: the search asks for hundreds of nearby α.
    let _grid = TableScope::new(TableSource::AlphaGrid);
    let m = 3 * pairs.len();
    let params = model.params;
    let residuals = |x: &[f64], out: &mut [f64]| {
        let p: Vec<f64> = params.iter().zip(x).map(|(q, x)| to_param(q, *x)).collect();
        if !residuals_of(&(model.spec)(&p), pairs, out) {
            out.fill(1e3);
        }
    };
    // Every combination of the per-parameter starts.
    let mut starts: Vec<Vec<f64>> = vec![Vec::new()];
    for q in params {
        starts = starts.into_iter().flat_map(|s| q.starts.iter().map(move |v| [s.clone(), vec![*v]].concat())).collect();
    }
    let best = starts
        .iter()
        .map(|s| {
            let x0: Vec<f64> = params.iter().zip(s).map(|(q, v)| from_param(q, *v)).collect();
            lm::minimize(&residuals, m, &x0, 100)
        })
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
        .expect("at least one start");
    let values: Vec<f64> = params.iter().zip(&best.x).map(|(q, x)| to_param(q, *x)).collect();
    let spec = (model.spec)(&values);
    let mut r = vec![0.0; m];
    residuals_of(&spec, pairs, &mut r);
    let signal: f64 = pairs.iter().map(|p| p.weight * p.target.iter().map(|t| t * t).sum::<f64>()).sum();
    let error = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut bands = [(0.0, 0.0); 8];
    for (k, p) in pairs.iter().enumerate() {
        let band = ((f64::from(p.wi.z).acos().to_degrees() / 10.0) as usize).min(7);
        bands[band].0 += (0..3).map(|c| r[3 * k + c] * r[3 * k + c]).sum::<f64>();
        bands[band].1 += p.weight * p.target.iter().map(|t| t * t).sum::<f64>();
    }
    let per_angle = bands.iter().enumerate().map(|(i, (e, s))| (10.0 * i as f64, if *s > 0.0 { (e / s).sqrt() } else { 0.0 })).collect();
    Ok(Fit {
        model: model.name,
        values: params.iter().map(|q| q.name).zip(values).collect(),
        spec,
        error,
        relative_error: error / signal.sqrt().max(1e-300),
        per_angle,
    })
}

/// A fit as the Mitsuba XML file `gonio fit -o` writes: a comment naming the measured `source`, the model,
/// its relative error and the number of direction pairs, then the `<bsdf>` element.
#[must_use]
pub fn fit_file(fit: &Fit, source: &str, pairs: usize) -> String {
    // XML comments may not contain "--": hyphens in the source's name become U+2010.
    let comment = format!(
        "<!-- fitted by gonio to {}: model {}, relative error {:.4} (Ngan et al. 2005 metric, {pairs} direction pairs) -->\n",
        source.replace('-', "\u{2010}"),
        fit.model,
        fit.relative_error,
    );
    comment + &spec_to_xml(&fit.spec, None, 0)
}

/// A spec (Mitsuba's dictionary form, as the fitted models make them) as a Mitsuba XML `<bsdf>` element.
#[must_use]
pub fn spec_to_xml(spec: &Value, name: Option<&str>, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let ty = spec["type"].as_str().unwrap_or("diffuse");
    let name_attr = name.map(|n| format!(" name=\"{n}\"")).unwrap_or_default();
    let mut out = format!("{pad}<bsdf type=\"{ty}\"{name_attr}>\n");
    if let Value::Object(map) = spec {
        for (key, v) in map.iter().filter(|(k, _)| *k != "type") {
            let inner = " ".repeat(indent + 4);
            match v {
                Value::Number(n) => out += &format!("{inner}<float name=\"{key}\" value=\"{}\"/>\n", n.as_f64().unwrap_or(0.0)),
                Value::String(s) => out += &format!("{inner}<string name=\"{key}\" value=\"{s}\"/>\n"),
                Value::Bool(b) => out += &format!("{inner}<boolean name=\"{key}\" value=\"{b}\"/>\n"),
                Value::Array(items) => {
                    let list: Vec<String> = items.iter().map(|i| i.as_f64().unwrap_or(0.0).to_string()).collect();
                    if key == "weights" {
                        out += &format!("{inner}<string name=\"{key}\" value=\"{}\"/>\n", list.join(", "));
                    } else {
                        out += &format!("{inner}<rgb name=\"{key}\" value=\"{}\"/>\n", list.join(", "));
                    }
                }
                Value::Object(_) => out += &spec_to_xml(v, Some(key), indent + 4),
                Value::Null => {}
            }
        }
    }
    out + &format!("{pad}</bsdf>\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load_xml(spec: &Value) -> Bsdf {
        Bsdf::from_xml(&spec_to_xml(spec, None, 0), "fit.xml").unwrap()
    }

    /// A table made from known parameters (the shared MERL fixture: Lambertian ρ = (0.2, 0.1, 0.05) plus
    /// GGX copper α = 0.2), fitted with `ggx+diffuse`: α within 2 %, the Lambertian albedo within 1 %.
    #[test]
    fn fitting_a_table_recovers_its_parameters() {
        let (_, path, _) = crate::measured::fixtures::smooth();
        let target = Bsdf::from_json(&format!(r#"{{"type": "merl", "filename": "{}"}}"#, path.display())).unwrap();
        let set = pairs(&target, 12);
        let fit = fit(model("ggx+diffuse").unwrap(), &set).unwrap();
        eprintln!("{fit:?}");
        let get = |n: &str| fit.values.iter().find(|(k, _)| *k == n).unwrap().1;
        assert!((get("alpha") / 0.2 - 1.0).abs() < 0.02, "alpha {}", get("alpha"));
        for (name, rho) in [("kd.r", 0.2), ("kd.g", 0.1), ("kd.b", 0.05)] {
            assert!((get(name) / rho - 1.0).abs() < 0.01, "{name} {} vs {rho}", get(name));
        }
        assert!(fit.relative_error < 0.01, "{}", fit.relative_error);
        // The fitted model's XML loads and evaluates like the fitted spec.
        let (a, b) = (load_xml(&fit.spec), Bsdf::from_json(&fit.spec.to_string()).unwrap());
        let (wo, wi) = (Vec3::new(0.3, 0.2, 0.93).normalize(), Vec3::new(-0.2, -0.1, 0.97).normalize());
        assert_eq!(a.f(wo, wi), b.f(wo, wi));
    }

    /// A MERL table made by gonio's gonioreflectometer from Ashikhmin–Shirley with nu = nv = 60
    /// (equivalent Beckmann α = √(2/(e + 2)) ≈ 0.18), fitted with `ashikhmin_shirley`: the exponent within
    /// 2 % (stricter than α within 2 %, since dα/α = −½ de/(e + 2)), R_d within 1 %, R_s within 2 %.
    #[test]
    fn fitting_an_ashikhmin_shirley_table_recovers_its_parameters() {
        let spec = r#"{"type": "ashikhmin_shirley", "nu": 60, "nv": 60, "rd": [0.3, 0.2, 0.1], "rs": [0.08, 0.06, 0.04]}"#;
        let table = crate::measured::gonioreflectometer::measure(&Bsdf::from_json(spec).unwrap(), 1, "as").unwrap();
        let path = crate::measured::fixtures::scratch_dir().join("ashikhmin_shirley.binary");
        table.write(&path).unwrap();
        let target = Bsdf::from_json(&format!(r#"{{"type": "merl", "filename": "{}"}}"#, path.display())).unwrap();
        let fit = fit(model("ashikhmin_shirley").unwrap(), &pairs(&target, 12)).unwrap();
        eprintln!("{fit:?}");
        let get = |n: &str| fit.values.iter().find(|(k, _)| *k == n).unwrap().1;
        let e = get("exponent") / 60.0 - 1.0;
        eprintln!("exponent relative error {e:+.2e}");
        assert!(e.abs() < 0.02, "exponent {}", get("exponent"));
        for (name, v, tol) in [
            ("rd.r", 0.3, 0.01),
            ("rd.g", 0.2, 0.01),
            ("rd.b", 0.1, 0.01),
            ("rs.r", 0.08, 0.02),
            ("rs.g", 0.06, 0.02),
            ("rs.b", 0.04, 0.02),
        ] {
            let err = get(name) / v - 1.0;
            eprintln!("{name}: {} relative error {err:+.2e}", get(name));
            assert!(err.abs() < tol, "{name} {} vs {v}", get(name));
        }
        assert!(fit.relative_error < 0.01, "{}", fit.relative_error);
    }

    #[test]
    fn every_model_spec_loads_at_its_starts() {
        for m in MODELS {
            let p: Vec<f64> = m.params.iter().map(|q| q.starts[0]).collect();
            let spec = (m.spec)(&p);
            Bsdf::from_json(&spec.to_string()).unwrap_or_else(|e| panic!("{}: {e}", m.name));
            load_xml(&spec);
        }
        assert!(model("nope").unwrap_err().to_string().contains("ggx+diffuse"));
    }
}
