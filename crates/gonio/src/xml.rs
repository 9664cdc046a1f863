//! Values in Mitsuba's XML scene format: `$name` substitution, file resolution, points and vectors,
//! spectra and transforms. [`crate::props::Props::from_xml_element_in`] reads plugin elements with these;
//! [`crate::scene::mitsuba_xml`] handles the document level (defaults, includes, paths, ids).

use crate::error::{Error, Result};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::cie::{CIE_MAX, CIE_MIN};
use crate::spectrum::illuminant::{Blackbody, BlackbodyNormalization, Spectrum};
use crate::spectrum::named::{parse_spd, reflectance_to_rgb, spectrum_to_rgb, SpdError};
use crate::spectrum::piecewise::PiecewiseLinear;
use crate::spectrum::Rgb;
use glam::Vec3;
use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The state a plugin element is read in: parameters for `$name`, plugins with an `id` for `<ref>`, and
/// the directories file names are resolved against (searched in order).
#[derive(Clone, Debug, Default)]
pub struct XmlEnv {
    pub params: HashMap<String, String>,
    pub refs: HashMap<String, Props>,
    pub search_paths: Vec<PathBuf>,
    /// A `<ref>` to an id not declared yet becomes a placeholder, resolved once the whole scene is read
    /// ([`Props::resolve_refs`]), as Mitsuba 3 allows; otherwise it is an error at once.
    pub forward_refs: bool,
    /// Things accepted but worth a note (e.g. a `<rotate>` axis that is not of unit length).
    pub warnings: std::cell::RefCell<Vec<String>>,
    /// Every file [`XmlEnv::resolve_file`] found, in order (a scene's assets: meshes, images, measured
    /// data, spectra), so that a scene can be shipped with them (`gonio.distributed`).
    pub files: std::cell::RefCell<Vec<PathBuf>>,
    /// Bytes produced by `$name` substitution so far (checked against [`MAX_SUBSTITUTED_TOTAL`]).
    substituted: Cell<usize>,
}

/// Limits on `$name` substitution (2026-11, issue 8): a `<default>` may use the ones before it, so ten
/// defaults that each repeat the previous one ten times would otherwise expand a few hundred bytes into
/// 10¹⁰ (the "billion laughs" pattern of XML entities). One substituted value may be at most
/// [`MAX_SUBSTITUTED_VALUE`] bytes, and one document may produce at most [`MAX_SUBSTITUTED_TOTAL`].
pub const MAX_SUBSTITUTED_VALUE: usize = 1 << 16;
pub const MAX_SUBSTITUTED_TOTAL: usize = 1 << 26;

/// Elements may nest at most this deep. `roxmltree`'s tokenizer recurses once per element level, so a
/// document of 100 000 nested elements (a few hundred KB) overflows the stack and aborts the process
/// (found by fuzzing, 2026-11); [`parse_document`] counts the depth before handing the text to it.
pub const MAX_ELEMENT_DEPTH: usize = 256;

/// Parse an XML document: the nesting depth is checked first (see [`MAX_ELEMENT_DEPTH`]); DTDs, and
/// with them entity expansion ("billion laughs"), are refused by `roxmltree`. `source` names the text.
pub fn parse_document<'a>(text: &'a str, source: &str) -> Result<roxmltree::Document<'a>> {
    check_depth(text, source)?;
    roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        Error::Syntax { at: format!("{source}:{}:{}", p.row, p.col), message: format!("not valid XML: {e}") }
    })
}

/// A linear scan of the element structure: `<name` opens (unless it ends in `/>`), `</` closes;
/// comments, CDATA, processing instructions and declarations are skipped. Over-counting malformed text is
/// harmless: the parser rejects it anyway.
fn check_depth(text: &str, source: &str) -> Result<()> {
    let bytes = text.as_bytes();
    let (mut depth, mut i) = (0usize, 0usize);
    let skip_to =
        |from: usize, end: &[u8]| bytes[from..].windows(end.len()).position(|w| w == end).map_or(bytes.len(), |k| from + k + end.len());
    while i < bytes.len() {
        match bytes[i] {
            b'<' if bytes[i..].starts_with(b"<!--") => i = skip_to(i + 4, b"-->"),
            b'<' if bytes[i..].starts_with(b"<![CDATA[") => i = skip_to(i + 9, b"]]>"),
            b'<' if bytes[i..].starts_with(b"<?") => i = skip_to(i + 2, b"?>"),
            b'<' if bytes[i..].starts_with(b"<!") => i = skip_to(i + 2, b">"),
            b'<' if bytes[i..].starts_with(b"</") => {
                depth = depth.saturating_sub(1);
                i += 2;
            }
            b'<' => {
                // An opening tag: find its end, outside quoted attribute values.
                let start = i;
                let mut quote = None;
                i += 1;
                while i < bytes.len() {
                    match (quote, bytes[i]) {
                        (None, q @ (b'"' | b'\'')) => quote = Some(q),
                        (Some(q), c) if c == q => quote = None,
                        (None, b'>') => break,
                        _ => {}
                    }
                    i += 1;
                }
                if bytes[i.saturating_sub(1)] != b'/' {
                    depth += 1;
                    if depth > MAX_ELEMENT_DEPTH {
                        let line = bytes[..start].iter().filter(|&&b| b == b'\n').count() + 1;
                        let line_start = bytes[..start].iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1);
                        let col = String::from_utf8_lossy(&bytes[line_start..start]).chars().count() + 1;
                        return Err(Error::Syntax {
                            at: format!("{source}:{line}:{col}"),
                            message: format!("elements nested more than {MAX_ELEMENT_DEPTH} deep"),
                        });
                    }
                }
            }
            _ => i += 1,
        }
    }
    Ok(())
}

/// A document's name with an index of its text, so that "file:line:col" of any byte offset costs
/// O(log n) (two binary searches) instead of a scan from the start.
///
/// `roxmltree::Document::text_pos_at` scans the text up to the offset on every call, and the loaders
/// compute the place of every element and attribute they read (for their messages), so loading was
/// quadratic in the file size: a 125 KB plugin with 5000 parameters took seconds (2026-11, issue 8).
/// The index is built once per document, in one pass; positions are the same as `text_pos_at`'s (line =
/// newlines before the offset + 1, column = characters since the last newline + 1).
#[derive(Clone, Debug)]
pub struct XmlSource<'t> {
    name: &'t str,
    len: usize,
    /// Byte offsets of every `\n`.
    newlines: Vec<usize>,
    /// Byte offsets of every UTF-8 continuation byte (none in ASCII text), so that a column counts
    /// characters even on a long line without scanning it.
    continuations: Vec<usize>,
}

thread_local! {
    /// Line indices built and binary-search steps taken on this thread: a deterministic measure of the
    /// position work of a load, for the tests that it is linear in the file size.
    static POSITION_WORK: Cell<PositionWork> = const { Cell::new(PositionWork { builds: 0, bytes_indexed: 0, lookups: 0, steps: 0 }) };
}

/// What the position lookups of this thread cost so far (see [`XmlSource`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PositionWork {
    /// Line indices built, and the bytes they scanned.
    pub builds: usize,
    pub bytes_indexed: usize,
    /// Positions looked up, and the binary-search steps they took.
    pub lookups: usize,
    pub steps: usize,
}

impl PositionWork {
    /// The total on this thread so far.
    #[must_use]
    pub fn current() -> PositionWork {
        POSITION_WORK.with(Cell::get)
    }

    fn add(f: impl FnOnce(&mut PositionWork)) {
        POSITION_WORK.with(|w| {
            let mut v = w.get();
            f(&mut v);
            w.set(v);
        });
    }
}

impl<'t> XmlSource<'t> {
    /// Index `text` (one pass), which messages call `name`.
    #[must_use]
    pub fn new(name: &'t str, text: &str) -> Self {
        let bytes = text.as_bytes();
        let newlines = bytes.iter().enumerate().filter(|&(_, &b)| b == b'\n').map(|(i, _)| i).collect();
        let continuations = bytes.iter().enumerate().filter(|&(_, &b)| b & 0xC0 == 0x80).map(|(i, _)| i).collect();
        PositionWork::add(|w| {
            w.builds += 1;
            w.bytes_indexed += bytes.len();
        });
        XmlSource { name, len: bytes.len(), newlines, continuations }
    }

    /// The name messages give the document.
    #[must_use]
    pub fn name(&self) -> &'t str {
        self.name
    }

    /// Line and column (both from 1, the column in characters) of byte `offset` (clamped to the text).
    #[must_use]
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.len);
        // Newlines before the offset, and where its line starts.
        let line = self.newlines.partition_point(|&n| n < offset);
        let line_start = if line == 0 { 0 } else { self.newlines[line - 1] + 1 };
        // Characters on the line before the offset: its bytes less their continuation bytes.
        let continued = self.continuations.partition_point(|&c| c < offset) - self.continuations.partition_point(|&c| c < line_start);
        PositionWork::add(|w| {
            w.lookups += 1;
            w.steps += log2_steps(self.newlines.len()) + 2 * log2_steps(self.continuations.len());
        });
        (line + 1, offset - line_start - continued + 1)
    }

    /// "file:line:col" of byte `offset`.
    #[must_use]
    pub fn at_offset(&self, offset: usize) -> String {
        let (line, col) = self.line_col(offset);
        format!("{}:{line}:{col}", self.name)
    }
}

/// The steps of a binary search over `n` items.
fn log2_steps(n: usize) -> usize {
    (usize::BITS - n.leading_zeros()) as usize + 1
}

/// "file:line:col" of a node (O(log n), see [`XmlSource`]).
#[must_use]
pub fn xml_at(source: &XmlSource, node: roxmltree::Node) -> String {
    source.at_offset(node.range().start)
}

impl XmlEnv {
    /// Replace every `$name` in `raw` by its parameter value.
    pub fn substitute(&self, raw: &str, at: &str) -> Result<String> {
        if !raw.contains('$') {
            return Ok(raw.to_string());
        }
        let mut out = String::with_capacity(raw.len());
        let mut rest = raw;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let tail = &rest[i + 1..];
            let len = tail.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(tail.len());
            let name = &tail[..len];
            let value = self.params.get(name).ok_or_else(|| {
                Error::spec(at, format!("`${name}` is not defined (add <default name=\"{name}\" value=\"…\"/> or pass -D {name}=…)"))
            })?;
            if out.len() + value.len() > MAX_SUBSTITUTED_VALUE {
                return Err(Error::spec(at, format!("`${name}` expands to more than {MAX_SUBSTITUTED_VALUE} bytes")));
            }
            out.push_str(value);
            rest = &tail[len..];
        }
        out.push_str(rest);
        let total = self.substituted.get() + out.len();
        if total > MAX_SUBSTITUTED_TOTAL || out.len() > MAX_SUBSTITUTED_VALUE {
            return Err(Error::spec(at, format!("`$` substitutions produce more than {MAX_SUBSTITUTED_TOTAL} bytes in all")));
        }
        self.substituted.set(total);
        Ok(out)
    }

    /// An attribute with parameters substituted.
    pub fn attr(&self, node: roxmltree::Node, name: &str, source: &XmlSource) -> Result<Option<String>> {
        // The place is only needed for a `$` (and costs a lookup).
        node.attribute(name)
            .map(|raw| if raw.contains('$') { self.substitute(raw, &xml_at(source, node)) } else { Ok(raw.to_string()) })
            .transpose()
    }

    /// A required attribute with parameters substituted.
    pub fn required(&self, node: roxmltree::Node, name: &str, source: &XmlSource) -> Result<String> {
        self.attr(node, name, source)?
            .ok_or_else(|| Error::spec(xml_at(source, node), format!("<{}> needs a `{name}` attribute", node.tag_name().name())))
    }

    /// A file name resolved against the search paths (an absolute name is taken as is).
    pub fn resolve_file(&self, name: &str, at: &str) -> Result<PathBuf> {
        let p = Path::new(name);
        let found = if p.is_absolute() {
            if p.exists() {
                Ok(p.to_path_buf())
            } else {
                Err(Error::spec(at, format!("file `{name}` does not exist")))
            }
        } else {
            self.search_paths.iter().map(|dir| dir.join(p)).find(|c| c.exists()).ok_or_else(|| {
                let dirs: Vec<String> = self.search_paths.iter().map(|d| d.display().to_string()).collect();
                Error::spec(at, format!("file `{name}` not found (searched: {})", dirs.join(", ")))
            })
        }?;
        self.files.borrow_mut().push(found.clone());
        Ok(found)
    }
}

/// Numbers separated by commas and/or whitespace.
#[must_use]
pub fn parse_numbers(s: &str) -> Option<Vec<f64>> {
    let parts: Vec<&str> = s.split(|c: char| c == ',' || c.is_whitespace()).filter(|p| !p.is_empty()).collect();
    if parts.is_empty() {
        return None;
    }
    parts.into_iter().map(|p| p.parse::<f64>().ok()).collect()
}

/// A vector given as `value="x, y, z"` (or one number for all three) or as `x`, `y`, `z` attributes,
/// each defaulting to `default` (0 for points, 1 for `<scale>`).
pub fn parse_vector(node: roxmltree::Node, env: &XmlEnv, source: &XmlSource, default: f32) -> Result<Vec3> {
    let at = xml_at(source, node);
    if let Some(v) = env.attr(node, "value", source)? {
        return match parse_numbers(&v).as_deref() {
            Some([x, y, z]) => Ok(Vec3::new(*x as f32, *y as f32, *z as f32)),
            Some([s]) => Ok(Vec3::splat(*s as f32)),
            _ => Err(Error::spec(at, format!("<{}>: expected \"x, y, z\", got \"{v}\"", node.tag_name().name()))),
        };
    }
    let mut out = Vec3::splat(default);
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        if let Some(v) = env.attr(node, axis, source)? {
            out[i] = v
                .trim()
                .parse::<f32>()
                .map_err(|_| Error::spec(&at, format!("<{}>: attribute `{axis}` must be a number, got \"{v}\"", node.tag_name().name())))?;
        }
    }
    Ok(out)
}

/// `<spectrum value="0.5"/>` (uniform), `value="400:0.1, 500:0.3, …"` or `filename="x.spd"`, and the
/// spectrum plugins `<spectrum type="d65">` (optional `scale`), `type="blackbody"` (`temperature` in K) and
/// `type="uniform"` (`value`): reduced to linear sRGB as Mitsuba's RGB variants do, and kept as the
/// spectrum too, for spectral mode (docs/spectral.md): inside an `<emitter>` every spectrum but a grey one,
/// elsewhere a table (a reflectance, a conductor's `eta`/`k`, a dielectric's `int_ior`/`ext_ior`).
///
/// Inside an `<emitter>` the spectrum is radiance: [`spectrum_to_rgb`] (no illuminant). A uniform value v
/// there is the equal-energy spectrum v, linear sRGB v·(1.2049, 0.9482, 0.9093), as in Mitsuba 3 (its RGB
/// and spectral variants alike, checked on 3.9.1 on 2026-12-06: (1.2048, 0.9483, 0.9089); gonio read it as
/// (v, v, v) before); `d65` is D65 of luminance `scale`, (1, 1, 1) × `scale`; a `blackbody` is Planck's
/// law in W·m⁻²·sr⁻¹·nm⁻¹ over [360, 830] nm (Mitsuba 3 renders it in its spectral variants only; gonio's
/// RGB mode takes its reduction). Elsewhere a spectrum is reduced as Mitsuba does, as seen under D65, so
/// that a flat spectrum stays grey ([`reflectance_to_rgb`], the one reduction of reflectance spectra, also
/// used by spectral RGL files; also for a conductor's `eta` and `k`, which Mitsuba reduces the same way,
/// unclamped: Cu's `.spd` files give η = (0.105, 0.977, 1.203) there, where `material="Cu"` gives
/// (0.201, 0.924, 1.102)).
pub fn parse_spectrum(node: roxmltree::Node, env: &XmlEnv, source: &XmlSource, within_emitter: bool) -> Result<(Rgb, Option<Spectrum>)> {
    let at = xml_at(source, node);
    let tabulated = |w: Vec<f64>, v: Vec<f64>| -> Result<(Rgb, Option<Spectrum>)> {
        tabulated_spectrum(w, v, within_emitter).map_err(|e| Error::spec(&at, format!("<spectrum>: {e}")))
    };
    if let Some(kind) = env.attr(node, "type", source)? {
        return spectrum_plugin(node, env, source, &kind, within_emitter);
    }
    if let Some(file) = env.attr(node, "filename", source)? {
        let path = env.resolve_file(&file, &at)?;
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Io { path: path.clone(), source })?;
        let (w, v) = parse_spd(&text).map_err(|e| Error::spec(&at, format!("{}: {e}", path.display())))?;
        return tabulated(w, v);
    }
    let raw = env.required(node, "value", source)?;
    if !raw.contains(':') {
        return match parse_numbers(&raw).as_deref() {
            Some([v]) => Ok(uniform_spectrum(*v, within_emitter)),
            _ => Err(Error::spec(at, format!("<spectrum>: expected a number or \"λ:value, …\" pairs, got \"{raw}\""))),
        };
    }
    let mut wavelengths = Vec::new();
    let mut values = Vec::new();
    for pair in raw.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let parsed = pair.split_once(':').and_then(|(l, v)| Some((l.trim().parse::<f64>().ok()?, v.trim().parse::<f64>().ok()?)));
        let Some((l, v)) = parsed else {
            return Err(Error::spec(at, format!("<spectrum>: expected \"wavelength:value\", got \"{pair}\"")));
        };
        if wavelengths.last().is_some_and(|&prev| l <= prev) {
            return Err(Error::spec(
                at,
                format!("<spectrum>: wavelengths must increase, {l} follows {}", wavelengths.last().unwrap_or(&0.0)),
            ));
        }
        wavelengths.push(l);
        values.push(v);
    }
    if wavelengths.len() < 2 {
        return Err(Error::spec(at, "<spectrum>: a wavelength list needs at least two entries"));
    }
    tabulated(wavelengths, values)
}

/// A spectrum given as `values` at ascending `wavelengths` (nm): its RGB reduction — radiance inside an
/// emitter ([`spectrum_to_rgb`]), else the colour under D65 ([`reflectance_to_rgb`]) — and the table, which
/// spectral mode renders. The XML `<spectrum>` and the dictionary `{"type": "spectrum"}` both read through it.
pub(crate) fn tabulated_spectrum(
    wavelengths: Vec<f64>,
    values: Vec<f64>,
    within_emitter: bool,
) -> std::result::Result<(Rgb, Option<Spectrum>), SpdError> {
    let table = PiecewiseLinear::new(wavelengths, values)?;
    let (w, v) = (table.wavelengths(), table.values());
    let rgb = if within_emitter { spectrum_to_rgb(w, v) } else { reflectance_to_rgb(w, v) };
    Ok((rgb, Some(Spectrum::Tabulated(table))))
}

/// A uniform spectrum of value `v`: inside an emitter the equal-energy spectrum (kept, for spectral mode),
/// elsewhere the grey `v` (see [`parse_spectrum`]).
pub(crate) fn uniform_spectrum(v: f64, within_emitter: bool) -> (Rgb, Option<Spectrum>) {
    if within_emitter {
        (spectrum_to_rgb(&[CIE_MIN, CIE_MAX], &[v, v]), Some(Spectrum::Constant(v)))
    } else {
        #[allow(clippy::cast_possible_truncation)]
        (Rgb::splat(v as f32), None)
    }
}

/// `<spectrum type="…">` (see [`parse_spectrum`]): its `<float>` parameters, each taken once.
fn spectrum_plugin(
    node: roxmltree::Node,
    env: &XmlEnv,
    source: &XmlSource,
    kind: &str,
    within_emitter: bool,
) -> Result<(Rgb, Option<Spectrum>)> {
    let at = xml_at(source, node);
    let Some(accepted) = spectrum_plugin_parameters(kind) else {
        return Err(Error::spec(
            at,
            format!("<spectrum type=\"{kind}\">: gonio reads the spectrum types d65, blackbody and uniform, and <spectrum value=…> or filename=…"),
        ));
    };
    let mut floats: Vec<(String, f64)> = Vec::new();
    for child in node.children().filter(roxmltree::Node::is_element) {
        let cat = xml_at(source, child);
        let name = env.attr(child, "name", source)?.unwrap_or_default();
        if child.tag_name().name() != "float" || !accepted.contains(&name.as_str()) || floats.iter().any(|(n, _)| *n == name) {
            return Err(Error::spec(cat, format!("<spectrum type=\"{kind}\"> takes <float name=…> once each of: {}", accepted.join(", "))));
        }
        let raw = env.required(child, "value", source)?;
        let v = raw
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| Error::spec(&cat, format!("`{name}`: expected a number, got \"{raw}\"")))?;
        floats.push((name, v));
    }
    spectrum_of_plugin(kind, &floats, within_emitter).map_err(|e| Error::spec(at, format!("<spectrum type=\"{kind}\">: {e}")))
}

/// The parameters of the spectrum plugin `kind` (`d65`, `blackbody`, `uniform`), `None` for another.
pub(crate) fn spectrum_plugin_parameters(kind: &str) -> Option<&'static [&'static str]> {
    match kind {
        "d65" => Some(&["scale"]),
        "blackbody" => Some(&["temperature"]),
        "uniform" => Some(&["value"]),
        _ => None,
    }
}

/// The spectrum plugin `d65`, `blackbody` or `uniform` with its numeric `parameters` (checked by the caller against
/// [`spectrum_plugin_parameters`]): its RGB reduction and, inside an emitter, its spectrum (see
/// [`parse_spectrum`]). The XML `<spectrum type=…>` and the dictionary `{"type": "d65"}` read through it; the
/// error is the problem alone, for the caller to place.
pub(crate) fn spectrum_of_plugin(
    kind: &str,
    parameters: &[(String, f64)],
    within_emitter: bool,
) -> std::result::Result<(Rgb, Option<Spectrum>), String> {
    let get = |name: &str| parameters.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    match kind {
        "d65" => {
            let scale = get("scale").unwrap_or(1.0);
            #[allow(clippy::cast_possible_truncation)]
            Ok((Rgb::splat(scale as f32), within_emitter.then_some(Spectrum::D65 { scale })))
        }
        "blackbody" => {
            let temperature = get("temperature").ok_or("needs a `temperature` (K)")?;
            if !within_emitter || !(temperature > 0.0) {
                return Err("an emitter's spectrum, with a temperature > 0 K".into());
            }
            let body = Blackbody::new(temperature, BlackbodyNormalization::Radiance);
            let w: Vec<f64> = (0..=470).map(|i| CIE_MIN + f64::from(i)).collect();
            let v: Vec<f64> = w.iter().map(|&l| body.eval(l)).collect();
            Ok((spectrum_to_rgb(&w, &v), Some(Spectrum::Blackbody(body))))
        }
        "uniform" => Ok(uniform_spectrum(get("value").ok_or("needs a `value`")?, within_emitter)),
        _ => Err(format!("not a spectrum plugin gonio reads: `{kind}`")),
    }
}

/// Mitsuba 3's `<rotate>` (`Transform4f::rotate`): M = cos θ I + (1 − cos θ) a aᵀ + sin θ [a]×, with the
/// axis `a` *as given*. For a unit axis that is the rotation by θ about it (Rodrigues' formula); Mitsuba 3
/// does not normalise (Mitsuba 0.6 did), so a longer axis also stretches: 3.9.1 loads `<rotate x="0" y="1"
/// z="1" angle="30"/>` as the rows (0.866, −0.5, 0.5), (0.5, 1, 0.134), (−0.5, 0.134, 1), and gonio does
/// the same so that such a file renders as in Mitsuba 3. `None` when the matrix is singular.
#[must_use]
pub fn mitsuba_rotate(axis: Vec3, angle_deg: f32) -> Option<Transform> {
    let a = axis.as_dvec3();
    let (sin, cos) = f64::from(angle_deg).to_radians().sin_cos();
    let c = 1.0 - cos;
    #[rustfmt::skip]
    let rows = [
        cos + c * a.x * a.x,       c * a.x * a.y - sin * a.z, c * a.x * a.z + sin * a.y, 0.0,
        c * a.y * a.x + sin * a.z, cos + c * a.y * a.y,       c * a.y * a.z - sin * a.x, 0.0,
        c * a.z * a.x - sin * a.y, c * a.z * a.y + sin * a.x, cos + c * a.z * a.z,       0.0,
        0.0,                       0.0,                       0.0,                       1.0,
    ];
    Transform::from_rows(&rows)
}

/// A `<transform>` element: its operations in document order, each left-multiplying the result so far
/// (Mitsuba's order: the first operation is applied to the object first).
pub fn parse_transform(node: roxmltree::Node, env: &XmlEnv, source: &XmlSource) -> Result<Transform> {
    let mut acc = Transform::IDENTITY;
    for op in node.children().filter(roxmltree::Node::is_element) {
        let at = xml_at(source, op);
        let tag = op.tag_name().name();
        let bad = |what: &str| Error::spec(&at, format!("<{tag}>: {what}"));
        let t = match tag {
            "translate" => Transform::translate(parse_vector(op, env, source, 0.0)?),
            "scale" => Transform::scale(parse_vector(op, env, source, 1.0)?).ok_or_else(|| bad("a scale factor is zero"))?,
            "rotate" => {
                let axis = parse_vector(op, env, source, 0.0)?;
                let angle = env.required(op, "angle", source)?;
                let angle: f32 = angle.trim().parse().map_err(|_| bad(&format!("`angle` must be a number of degrees, got \"{angle}\"")))?;
                if axis == Vec3::ZERO {
                    return Err(bad("the rotation axis is zero (give x, y and/or z)"));
                }
                if (axis.length() - 1.0).abs() > 1e-4 {
                    env.warnings.borrow_mut().push(format!(
                        "{at}: <rotate> axis ({}, {}, {}) is not of unit length: as in Mitsuba 3, the matrix is built from it as \
                         given, which rotates and stretches (normalise the axis for a pure rotation)",
                        axis.x, axis.y, axis.z
                    ));
                }
                mitsuba_rotate(axis, angle).ok_or_else(|| bad("the transform is singular"))?
            }
            "matrix" => {
                let v = env.required(op, "value", source)?;
                let m: [f64; 16] = match parse_numbers(&v) {
                    Some(m) if m.len() == 16 => std::array::from_fn(|i| m[i]),
                    Some(m) => return Err(bad(&format!("expected 16 numbers (row-major 4×4), got {}", m.len()))),
                    None => return Err(bad(&format!("expected 16 numbers, got \"{v}\""))),
                };
                Transform::from_rows(&m).ok_or_else(|| bad("the matrix is singular"))?
            }
            "lookat" => {
                let vec = |name: &str| -> Result<Vec3> {
                    let v = env.required(op, name, source)?;
                    match parse_numbers(&v).as_deref() {
                        Some([x, y, z]) => Ok(Vec3::new(*x as f32, *y as f32, *z as f32)),
                        _ => Err(bad(&format!("`{name}` must be \"x, y, z\", got \"{v}\""))),
                    }
                };
                let (origin, target) = (vec("origin")?, vec("target")?);
                let up = if op.attribute("up").is_some() { vec("up")? } else { Vec3::Y };
                Transform::look_at(origin, target, up)
                    .ok_or_else(|| bad("origin equals target, or `up` is parallel to the view direction"))?
            }
            _ => return Err(bad("unknown transform operation (expected translate, rotate, scale, matrix or lookat)")),
        };
        for a in op.attributes() {
            let known: &[&str] = match tag {
                "translate" | "scale" => &["x", "y", "z", "value"],
                "rotate" => &["x", "y", "z", "angle", "value"],
                "matrix" => &["value"],
                _ => &["origin", "target", "up"],
            };
            if !known.contains(&a.name()) {
                return Err(bad(&format!("unknown attribute `{}` (expected {})", a.name(), known.join(", "))));
            }
        }
        acc = t.then_after(acc);
    }
    Ok(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first<'a, 'b>(doc: &'a roxmltree::Document<'b>) -> roxmltree::Node<'a, 'b> {
        doc.root_element()
    }

    #[test]
    fn line_index_positions_equal_roxmltree() {
        // Newlines, CRLF, multi-byte characters (2, 3 and 4 bytes), an empty line, and one long line.
        let long = format!("<a>{}</a>", "<b x=\"é\"/>".repeat(500));
        for text in ["<a>\n  <b/>\r\n\n<c x=\"ü€😀\"/>😀<d/>\n</a>", "<scène>\n\t<ü/></scène>\n", long.as_str(), "<a/>"] {
            let doc = roxmltree::Document::parse(text).unwrap();
            let source = XmlSource::new("p.xml", text);
            for offset in (0..=text.len() + 2).filter(|&i| i > text.len() || text.is_char_boundary(i)) {
                let want = doc.text_pos_at(offset);
                assert_eq!(source.line_col(offset), (want.row as usize, want.col as usize), "offset {offset} of {text:?}");
            }
            for node in doc.descendants() {
                let want = doc.text_pos_at(node.range().start);
                assert_eq!(xml_at(&source, node), format!("p.xml:{}:{}", want.row, want.col));
            }
        }
    }

    #[test]
    fn transform_ops_compose_left() {
        let doc = roxmltree::Document::parse(
            "<transform name=\"to_world\"><scale value=\"2\"/><rotate z=\"1\" angle=\"90\"/><translate x=\"1\"/></transform>",
        )
        .unwrap();
        let t = parse_transform(first(&doc), &XmlEnv::default(), &XmlSource::new("t.xml", doc.input_text())).unwrap();
        assert!((t.point(Vec3::X) - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-5);
        let doc = roxmltree::Document::parse("<transform><matrix value=\"1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1\"/></transform>").unwrap();
        let t = parse_transform(first(&doc), &XmlEnv::default(), &XmlSource::new("t.xml", doc.input_text())).unwrap();
        assert!((t.point(Vec3::ZERO) - Vec3::new(5.0, 6.0, 7.0)).length() < 1e-6);
    }

    /// `<rotate>` as Mitsuba 3.9.1 loads it: a unit axis gives the rotation gonio's `Transform::rotate`
    /// gives; the axis (0, 1, 1) gives Mitsuba's unnormalised matrix (printed by `mi.traverse`), with a warning.
    #[test]
    fn rotate_uses_the_axis_as_given_like_mitsuba() {
        let unit = mitsuba_rotate(Vec3::new(0.0, 0.6, 0.8), 37.0).unwrap();
        let glam_rotation = Transform::rotate(Vec3::new(0.0, 0.6, 0.8), 37.0).unwrap();
        for p in [Vec3::X, Vec3::Y, Vec3::new(0.3, -2.0, 1.0)] {
            assert!((unit.point(p) - glam_rotation.point(p)).length() < 1e-5, "{p}");
        }
        let doc = roxmltree::Document::parse("<transform>\n<rotate x=\"0\" y=\"1\" z=\"1\" angle=\"30\"/></transform>").unwrap();
        let env = XmlEnv::default();
        let t = parse_transform(first(&doc), &env, &XmlSource::new("t.xml", doc.input_text())).unwrap();
        let rows = [[0.866_025, -0.5, 0.5], [0.5, 1.0, 0.133_975], [-0.5, 0.133_975, 1.0]];
        for (j, col) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
            let got = t.vector(col);
            for i in 0..3 {
                assert!((got[i] - rows[i][j]).abs() < 1e-5, "row {i} col {j}: {}", got[i]);
            }
        }
        let warnings = env.warnings.borrow();
        assert!(warnings.len() == 1 && warnings[0].starts_with("t.xml:2:1: <rotate> axis (0, 1, 1) is not of unit length"), "{warnings:?}");
    }

    #[test]
    fn bad_transforms_name_the_place() {
        for (xml, want) in [
            ("<transform>\n<rotate angle=\"3\"/></transform>", "t.xml:2:1: <rotate>: the rotation axis is zero"),
            ("<transform>\n<skew x=\"1\"/></transform>", "t.xml:2:1: <skew>: unknown transform"),
            ("<transform>\n<matrix value=\"1 2 3\"/></transform>", "t.xml:2:1: <matrix>: expected 16 numbers"),
            ("<transform>\n<lookat origin=\"0,0,0\" target=\"0,0,0\"/></transform>", "t.xml:2:1: <lookat>: origin equals target"),
            ("<transform>\n<translate x=\"a\"/></transform>", "t.xml:2:1: <translate>: attribute `x`"),
            ("<transform>\n<scale x=\"0\"/></transform>", "t.xml:2:1: <scale>: a scale factor is zero"),
        ] {
            let doc = roxmltree::Document::parse(xml).unwrap();
            let e = parse_transform(first(&doc), &XmlEnv::default(), &XmlSource::new("t.xml", xml)).unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
        }
    }

    #[test]
    fn substitution_and_spectra() {
        let mut env = XmlEnv::default();
        env.params.insert("spp".into(), "64".into());
        assert_eq!(env.substitute("$spp", "x").unwrap(), "64");
        assert_eq!(env.substitute("a$spp-b", "x").unwrap(), "a64-b");
        assert!(env.substitute("$nope", "f.xml:3:4").unwrap_err().to_string().starts_with("f.xml:3:4: `$nope` is not defined"));
        let doc = roxmltree::Document::parse("<spectrum name=\"r\" value=\"400:0.78, 500:0.78, 600:0.78, 700:0.78\"/>").unwrap();
        let c = parse_spectrum(first(&doc), &env, &XmlSource::new("s.xml", doc.input_text()), false).unwrap().0;
        // Mitsuba 3.9.1 (scalar_rgb) loads these reflectances as (0.776367, 0.77981, 0.776029) and, three dips
        // to 0.05, (0.3456, 0.4363, 0.2434) (2026-12-06; before then gonio gave the second 0.4358 in red).
        let close = |c: Rgb, m: [f32; 3]| (0..3).all(|k| (c.0[k] / m[k] - 1.0).abs() < 1e-3);
        assert!(close(c, [0.776_367, 0.779_81, 0.776_029]), "{c}");
        let dips = "360:0.8, 450:0.05, 500:0.8, 550:0.05, 580:0.8, 610:0.05, 660:0.8, 830:0.8";
        let text = format!("<spectrum name=\"r\" value=\"{dips}\"/>");
        let doc = roxmltree::Document::parse(&text).unwrap();
        let (c, table) = parse_spectrum(first(&doc), &env, &XmlSource::new("s.xml", doc.input_text()), false).unwrap();
        assert!(close(c, [0.345_6, 0.436_3, 0.243_4]), "{c}");
        assert!(matches!(table, Some(Spectrum::Tabulated(t)) if t.eval(550.0) == 0.05), "the table is kept for spectral mode");
        let doc = roxmltree::Document::parse("<spectrum name=\"radiance\" value=\"400:0, 500:8, 600:15.6, 700:18.4\"/>").unwrap();
        let c = parse_spectrum(first(&doc), &env, &XmlSource::new("s.xml", doc.input_text()), true).unwrap().0;
        // Mitsuba 3.9.1 loads this area-light radiance as (20.7108, 10.8546, 2.77115).
        assert!(
            (c.r() / 20.7108 - 1.0).abs() < 2e-3 && (c.g() / 10.8546 - 1.0).abs() < 2e-3 && (c.b() / 2.77115 - 1.0).abs() < 5e-3,
            "{c}"
        );
    }
}
