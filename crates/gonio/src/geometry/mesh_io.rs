//! Triangle meshes from files: Wavefront OBJ, Stanford PLY and Mitsuba's `.serialized`.
//!
//! Every loader returns a [`MeshData`]: per-vertex positions, optional per-vertex normals and texture
//! coordinates, and triangles as index triples. Polygons are fan-triangulated (`v0 v1 v2`, `v0 v2 v3`, …).
//! Values are returned as stored: normals are not renormalised and texture coordinates are not flipped.
//!
//! All three treat the file as hostile: a count is checked against the bytes that remain before anything
//! is allocated from it, every index is range-checked, and a non-finite position is an error. Errors
//! ([`Error::Format`]) name the file and the line (text) or byte offset (binary).
//!
//! ## OBJ
//! `v`, `vt`, `vn` and `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn` references, negative (relative) indices;
//! `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p` and unknown statements are ignored. Vertices are
//! de-duplicated per unique (v, vt, vn) triple, so normals and texture coordinates become per-vertex.
//! Normals (texture coordinates) are returned only if every face corner references one.
//! Mitsuba 3's `obj` plugin flips the vertical texture coordinate by default (`flip_tex_coords = true`,
//! v → 1 − v) and normalises normals; this loader does neither, so a scene loader that wants Mitsuba's
//! behaviour calls [`MeshData::flip_tex_coords`].
//!
//! ## PLY
//! `ascii 1.0`, `binary_little_endian 1.0`, `binary_big_endian 1.0`. From the `vertex` element: `x y z`,
//! `nx ny nz`, and texture coordinates as `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`;
//! from the `face` element: the list `vertex_indices` (or `vertex_index`) with any count and index types.
//! Other scalar vertex properties become named attributes ([`VertexAttribute`], grouped as Mitsuba 3's
//! `ply` groups them: `color_0 color_1 color_2` or `red green blue` make `vertex_color`); integer-typed
//! colours (`uchar red`, …) are divided by 255. All other properties and elements are skipped by their
//! declared types.
//!
//! ## Mitsuba `.serialized`
//! The layout, as documented for Mitsuba's `serialized` shape plugin (Mitsuba 0.5 documentation,
//! §8.1 "Serialized mesh loader"; Mitsuba 3 reads the same files). All numbers are little-endian.
//!
//! | bytes | content |
//! |---|---|
//! | u16 | format identifier `0x041C` |
//! | u16 | version, 3 or 4 |
//! | rest of the mesh | one zlib stream, decompressing to the fields below |
//! | u32 | flags: `0x0001` vertex normals, `0x0002` texture coordinates, `0x0008` vertex colours, `0x0010` face normals (flat shading), `0x1000` single precision, `0x2000` double precision |
//! | NUL-terminated UTF-8 | the mesh name (version 4 only) |
//! | u64, u64 | vertex count, triangle count |
//! | 3 × float per vertex | positions; then normals, texture coordinates (2 × float) and colours (3 × float) if flagged; float is f32, or f64 with `0x2000` |
//! | 3 × index per triangle | u32 indices, or u64 when the vertex count exceeds 2³² − 1 |
//!
//! A file may hold several such meshes one after the other; it then ends with a dictionary: one offset
//! per mesh from the start of the file (u64 in version 4, u32 in version 3) followed by the u32 mesh count
//! as the last four bytes. When the face-normals flag is set, [`load_serialized`] returns no normals, so the
//! renderer shades with the geometric normal as Mitsuba does; vertex colours are read past and dropped.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};
use crate::math::{Vec2, Vec3};

/// A triangle mesh as read from a file: per-vertex attributes and index triples into them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// One per position when present.
    pub normals: Option<Vec<Vec3>>,
    /// One per position when present.
    pub uvs: Option<Vec<Vec2>>,
    /// Counter-clockwise as stored in the file; every index is `< positions.len()`.
    pub indices: Vec<[u32; 3]>,
    /// Further per-vertex values (PLY files), named as Mitsuba names them (`vertex_color`, …).
    pub attributes: Vec<VertexAttribute>,
}

/// A per-vertex attribute: `dim` values per vertex, vertex after vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexAttribute {
    pub name: String,
    pub dim: usize,
    pub values: Vec<f32>,
}

/// The attribute a PLY vertex property belongs to, as Mitsuba 3's `ply` groups them: a name
/// `{prefix}_{c}` with c one of x y z w, r g b a, 0 1 2 3 or 1 2 3 4 belongs to `vertex_{prefix}`, the bare
/// colour names (r g b a, red green blue alpha) to `vertex_color`, any other name to `vertex_{name}`
/// alone. Consecutive properties of one prefix make one attribute.
fn attribute_prefix(name: &str) -> &str {
    match name {
        "r" | "g" | "b" | "a" | "red" | "green" | "blue" | "alpha" => "color",
        _ => match name.rsplit_once('_') {
            Some((prefix, c)) if !prefix.is_empty() && ["x", "y", "z", "w", "r", "g", "b", "a", "0", "1", "2", "3", "4"].contains(&c) => {
                prefix
            }
            _ => name,
        },
    }
}

impl MeshData {
    /// Replaces every texture coordinate (u, v) by (u, 1 − v), the convention Mitsuba 3's `obj` plugin
    /// applies by default (`flip_tex_coords`).
    pub fn flip_tex_coords(&mut self) {
        if let Some(uvs) = &mut self.uvs {
            for uv in uvs {
                uv.y = 1.0 - uv.y;
            }
        }
    }

    /// Checks the invariants every loader promises: finite positions, attribute arrays as long as the
    /// position array, indices in range.
    fn validate(&self, path: &Path) -> Result<()> {
        let n = self.positions.len();
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::format(path, format!("vertex {i}"), format!("position {} is not finite", self.positions[i])));
        }
        for (what, len) in [("normals", self.normals.as_ref().map(Vec::len)), ("uvs", self.uvs.as_ref().map(Vec::len))] {
            if let Some(len) = len {
                if len != n {
                    return Err(Error::format(path, what, format!("expected {n} entries, found {len}")));
                }
            }
        }
        for (f, tri) in self.indices.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(Error::format(
                    path,
                    format!("triangle {f}"),
                    format!("vertex index {i} out of range: the mesh has {n} vertices"),
                ));
            }
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------------
// OBJ

/// Loads a Wavefront OBJ file (see the module docs for what is understood).
pub fn load_obj(path: &Path) -> Result<MeshData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    obj_from_bytes(path, &bytes)
}

/// Parses the content of an OBJ file; `path` only names it in errors.
pub fn obj_from_bytes(path: &Path, bytes: &[u8]) -> Result<MeshData> {
    parse_obj(path, &String::from_utf8_lossy(bytes))
}

/// One face corner: indices into the `v`, `vt`, `vn` arrays (`u32::MAX` for none).
type Corner = (u32, u32, u32);
const NONE: u32 = u32::MAX;

fn parse_obj(path: &Path, text: &str) -> Result<MeshData> {
    let mut v: Vec<Vec3> = Vec::new();
    let mut vt: Vec<Vec2> = Vec::new();
    let mut vn: Vec<Vec3> = Vec::new();
    let mut corners: HashMap<Corner, u32> = HashMap::new();
    let mut unique: Vec<Corner> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut polygon: Vec<u32> = Vec::new();

    for (line_index, raw) in text.lines().enumerate() {
        let at = || format!("line {}", line_index + 1);
        let line = raw.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else { continue };
        let floats = |tokens: std::str::SplitWhitespace, min: usize, max: usize| -> Result<Vec<f32>> {
            let values: Vec<&str> = tokens.collect();
            if values.len() < min || values.len() > max {
                return Err(Error::format(path, at(), format!("`{keyword}` expects {min} to {max} numbers, found {}", values.len())));
            }
            values
                .iter()
                .map(|s| s.parse::<f32>().map_err(|_| Error::format(path, at(), format!("expected a number, found `{s}`"))))
                .collect()
        };
        match keyword {
            "v" => {
                // x y z [w] (the weight is ignored), optionally followed by r g b vertex colours.
                let p = floats(tokens, 3, 7)?;
                let p = Vec3::new(p[0], p[1], p[2]);
                if !p.is_finite() {
                    return Err(Error::format(path, at(), format!("vertex position {p} is not finite")));
                }
                v.push(p);
            }
            "vt" => {
                let t = floats(tokens, 1, 3)?;
                vt.push(Vec2::new(t[0], t.get(1).copied().unwrap_or(0.0)));
            }
            "vn" => {
                let n = floats(tokens, 3, 3)?;
                vn.push(Vec3::new(n[0], n[1], n[2]));
            }
            "f" => {
                polygon.clear();
                for corner in tokens {
                    let c = parse_corner(corner, v.len(), vt.len(), vn.len())
                        .map_err(|message| Error::format(path, at(), format!("face corner `{corner}`: {message}")))?;
                    let next = u32::try_from(unique.len()).map_err(|_| Error::format(path, at(), "more than 2³² − 1 distinct vertices"))?;
                    let index = *corners.entry(c).or_insert_with(|| {
                        unique.push(c);
                        next
                    });
                    polygon.push(index);
                }
                if polygon.len() < 3 {
                    return Err(Error::format(path, at(), format!("a face needs at least 3 corners, found {}", polygon.len())));
                }
                for k in 1..polygon.len() - 1 {
                    indices.push([polygon[0], polygon[k], polygon[k + 1]]);
                }
            }
            _ => {} // o, g, s, usemtl, mtllib, l, p, … carry nothing a renderer needs from the mesh.
        }
    }

    let positions = unique.iter().map(|c| v[c.0 as usize]).collect();
    let uvs = unique.iter().all(|c| c.1 != NONE).then(|| unique.iter().map(|c| vt[c.1 as usize]).collect());
    let normals = unique.iter().all(|c| c.2 != NONE).then(|| unique.iter().map(|c| vn[c.2 as usize]).collect());
    let mesh = MeshData { positions, normals, uvs, indices, attributes: Vec::new() };
    mesh.validate(path)?;
    Ok(mesh)
}

/// Parses `v`, `v/vt`, `v//vn` or `v/vt/vn` into 0-based indices, resolving negative (relative) ones
/// against the counts read so far.
fn parse_corner(corner: &str, nv: usize, nvt: usize, nvn: usize) -> std::result::Result<Corner, String> {
    let mut parts = corner.split('/');
    let resolve = |s: Option<&str>, count: usize, what: &str, required: bool| -> std::result::Result<u32, String> {
        let s = match s {
            Some(s) if !s.is_empty() => s,
            _ if required => return Err(format!("missing {what} index")),
            _ => return Ok(NONE),
        };
        let i: i64 = s.parse().map_err(|_| format!("`{s}` is not an integer {what} index"))?;
        // OBJ indices are 1-based; negative ones count back from the latest element.
        let zero_based = if i > 0 { i - 1 } else { count as i64 + i };
        if i == 0 || zero_based < 0 || zero_based >= count as i64 {
            return Err(format!("{what} index {i} out of range: {count} defined so far"));
        }
        u32::try_from(zero_based).map_err(|_| format!("{what} index {i} too large"))
    };
    let v = resolve(parts.next(), nv, "vertex", true)?;
    let t = resolve(parts.next(), nvt, "texture", false)?;
    let n = resolve(parts.next(), nvn, "normal", false)?;
    if parts.next().is_some() {
        return Err("more than three `/`-separated indices".into());
    }
    Ok((v, t, n))
}

// ---------------------------------------------------------------------------------------------------
// PLY

/// Loads a Stanford PLY file, ascii or binary of either byte order (see the module docs).
pub fn load_ply(path: &Path) -> Result<MeshData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    ply_from_bytes(path, &bytes)
}

/// Parses the content of a PLY file; `path` only names it in errors.
pub fn ply_from_bytes(path: &Path, bytes: &[u8]) -> Result<MeshData> {
    parse_ply(path, bytes)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
enum Property {
    Scalar { name: String, ty: Scalar },
    List { name: String, count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// The body of a PLY file, read value by value whatever the encoding.
struct PlyBody<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    pos: usize,
    encoding: Encoding,
    /// The 1-based line of `pos`, for ascii bodies.
    line: usize,
}

/// Where a value of a PLY body starts: its line (ascii) or byte offset, made into text only for an error
/// (2026-12-05: formatting it for every value read was 6 % of loading a million-triangle mesh).
#[derive(Clone, Copy, Debug)]
struct At {
    encoding: Encoding,
    line: usize,
    pos: usize,
}

impl From<At> for String {
    fn from(at: At) -> String {
        match at.encoding {
            Encoding::Ascii => format!("line {}", at.line),
            _ => format!("byte {}", at.pos),
        }
    }
}

impl PlyBody<'_> {
    fn at(&self) -> At {
        At { encoding: self.encoding, line: self.line, pos: self.pos }
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn error(&self, message: impl Into<String>) -> Error {
        Error::format(self.path, self.at(), message)
    }

    /// Moves an ascii body to the start of its next token, so that [`Self::at`] names its line.
    fn skip_whitespace(&mut self) {
        if self.encoding == Encoding::Ascii {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                if self.bytes[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
        }
    }

    /// Where the next value starts.
    fn next_at(&mut self) -> At {
        self.skip_whitespace();
        self.at()
    }

    /// Reads one value of type `ty`, widened to `f64` (exact for every PLY type).
    fn read(&mut self, ty: Scalar) -> Result<f64> {
        match self.encoding {
            Encoding::Ascii => {
                self.skip_whitespace();
                let start = self.pos;
                while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
                    self.pos += 1;
                }
                if start == self.pos {
                    return Err(self.error(format!("unexpected end of file; expected a {ty:?} value")));
                }
                let token = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("?");
                let value: f64 = token.parse().map_err(|_| self.error(format!("expected a {ty:?} value, found `{token}`")))?;
                if !matches!(ty, Scalar::F32 | Scalar::F64) && value.fract() != 0.0 {
                    return Err(self.error(format!("expected an integer ({ty:?}), found `{token}`")));
                }
                Ok(value)
            }
            Encoding::LittleEndian | Encoding::BigEndian => Ok(match ty {
                Scalar::I8 => f64::from(i8::from_le_bytes(self.take(ty)?)),
                Scalar::U8 => f64::from(u8::from_le_bytes(self.take(ty)?)),
                Scalar::I16 => f64::from(i16::from_le_bytes(self.take(ty)?)),
                Scalar::U16 => f64::from(u16::from_le_bytes(self.take(ty)?)),
                Scalar::I32 => f64::from(i32::from_le_bytes(self.take(ty)?)),
                Scalar::U32 => f64::from(u32::from_le_bytes(self.take(ty)?)),
                Scalar::F32 => f64::from(f32::from_le_bytes(self.take(ty)?)),
                Scalar::F64 => f64::from_le_bytes(self.take(ty)?),
            }),
        }
    }

    /// The next `N` bytes of a binary body (a value of type `ty`, which names it in the error), in
    /// little-endian order. `N` is known where it is called, so the copy is one load (2026-12: a copy of
    /// `ty.size()` bytes had been a call to `memmove` per value).
    #[inline(always)]
    fn take<const N: usize>(&mut self, ty: Scalar) -> Result<[u8; N]> {
        debug_assert_eq!(N, ty.size());
        let Some(bytes) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(self.error(format!("unexpected end of file; expected a {ty:?} value")));
        };
        let mut raw = [0u8; N];
        raw.copy_from_slice(bytes);
        if self.encoding == Encoding::BigEndian {
            raw.reverse();
        }
        self.pos += N;
        Ok(raw)
    }

    /// Reads a list length: a non-negative integer.
    fn read_count(&mut self, ty: Scalar) -> Result<usize> {
        let at = self.next_at();
        let n = self.read(ty)?;
        if !(n >= 0.0 && n.fract() == 0.0 && n <= u32::MAX as f64) {
            return Err(Error::format(self.path, at, format!("list length {n} is not a non-negative integer")));
        }
        Ok(n as usize)
    }

    /// Before allocating for `count` records of `element`: checks that the remaining bytes can hold
    /// them (each binary value takes its size; each ascii value at least one character).
    fn check_count(&self, element: &Element) -> Result<()> {
        let min_record: usize = element
            .properties
            .iter()
            .map(|p| match (self.encoding, p) {
                (Encoding::Ascii, _) => 1,
                (_, Property::Scalar { ty, .. }) => ty.size(),
                (_, Property::List { count, .. }) => count.size(),
            })
            .sum();
        let needed = element.count.checked_mul(min_record.max(1));
        if !matches!(needed, Some(n) if n <= self.remaining()) {
            return Err(self.error(format!(
                "element `{}` declares {} records, more than the {} bytes left can hold",
                element.name,
                element.count,
                self.remaining()
            )));
        }
        Ok(())
    }
}

fn parse_ply_header(path: &Path, bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize)> {
    let mut pos = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for line_number in 1.. {
        let at = format!("line {line_number}");
        let Some(end) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(Error::format(path, at, "unexpected end of file in the header; expected `end_header`"));
        };
        let line = String::from_utf8_lossy(&bytes[pos..pos + end]);
        pos += end + 1;
        let tokens: Vec<&str> = line.split_whitespace().collect();
        let bad = |message: String| Error::format(path, format!("line {line_number}"), message);
        if line_number == 1 {
            if tokens != ["ply"] {
                return Err(bad("expected the magic word `ply`".into()));
            }
            continue;
        }
        match tokens.as_slice() {
            ["format", kind, version] => {
                if *version != "1.0" {
                    return Err(bad(format!("expected format version 1.0, found {version}")));
                }
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::LittleEndian,
                    "binary_big_endian" => Encoding::BigEndian,
                    _ => return Err(bad(format!("expected ascii, binary_little_endian or binary_big_endian, found `{kind}`"))),
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count.parse().map_err(|_| bad(format!("expected an element count, found `{count}`")))?;
                elements.push(Element { name: (*name).to_string(), count, properties: Vec::new() });
            }
            ["property", rest @ ..] => {
                let element = elements.last_mut().ok_or_else(|| bad("a property before any element".into()))?;
                let ty = |name: &str| Scalar::parse(name).ok_or_else(|| bad(format!("unknown property type `{name}`")));
                let property = match rest {
                    ["list", count, item, name] => Property::List { name: (*name).to_string(), count: ty(count)?, item: ty(item)? },
                    [t, name] => Property::Scalar { name: (*name).to_string(), ty: ty(t)? },
                    _ => return Err(bad(format!("malformed property line `{}`", line.trim()))),
                };
                element.properties.push(property);
            }
            ["end_header"] => {
                let encoding = encoding.ok_or_else(|| bad("`end_header` before any `format` line".into()))?;
                return Ok((encoding, elements, pos));
            }
            _ => return Err(bad(format!("unexpected header line `{}`", line.trim()))),
        }
    }
    unreachable!("the header loop only ends by returning")
}

fn parse_ply(path: &Path, bytes: &[u8]) -> Result<MeshData> {
    let (encoding, elements, body_start) = parse_ply_header(path, bytes)?;
    let header_lines = bytes[..body_start].iter().filter(|&&b| b == b'\n').count();
    let mut body = PlyBody { path, bytes, pos: body_start, encoding, line: header_lines + 1 };
    let mut mesh = MeshData::default();
    let mut saw_vertex = false;
    let mut saw_face = false;

    for element in &elements {
        body.check_count(element)?;
        match element.name.as_str() {
            "vertex" if !saw_vertex => {
                saw_vertex = true;
                read_ply_vertices(&mut body, element, &mut mesh)?;
            }
            "face" if !saw_face => {
                saw_face = true;
                read_ply_faces(&mut body, element, &mut mesh)?;
            }
            _ => {
                for _ in 0..element.count {
                    skip_record(&mut body, element)?;
                }
            }
        }
    }
    if !saw_vertex || !saw_face {
        return Err(Error::format(path, "header", "expected a `vertex` and a `face` element"));
    }
    mesh.validate(path)?;
    Ok(mesh)
}

fn skip_record(body: &mut PlyBody, element: &Element) -> Result<()> {
    for p in &element.properties {
        match p {
            Property::Scalar { ty, .. } => {
                body.read(*ty)?;
            }
            Property::List { count, item, .. } => {
                let n = body.read_count(*count)?;
                for _ in 0..n {
                    body.read(*item)?;
                }
            }
        }
    }
    Ok(())
}

fn read_ply_vertices(body: &mut PlyBody, element: &Element, mesh: &mut MeshData) -> Result<()> {
    // Which attribute each property feeds: 0..3 position, 3..6 normal, 6..8 texture coordinate.
    let slot = |name: &str| -> Option<usize> {
        Some(match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "nx" => 3,
            "ny" => 4,
            "nz" => 5,
            "u" | "s" | "texture_u" | "texture_s" => 6,
            "v" | "t" | "texture_v" | "texture_t" => 7,
            _ => return None,
        })
    };
    // Where each property's value goes, decided once rather than by its name per vertex: a slot of
    // `values`, or one of the other scalar properties' attributes, which group them (and whether it is an
    // integer colour, in 0..=255).
    enum Sink {
        Slot(usize),
        Attribute(usize, bool),
        Nowhere,
    }
    let mut attributes: Vec<VertexAttribute> = Vec::new();
    let mut sinks: Vec<Sink> = Vec::with_capacity(element.properties.len());
    // Consecutive properties of one prefix form an attribute; any other property between them ends it.
    let mut last_prefix: Option<&str> = None;
    for p in &element.properties {
        let sink = match p {
            Property::Scalar { name, ty } => match slot(name) {
                Some(s) => {
                    last_prefix = None;
                    Sink::Slot(s)
                }
                None => {
                    let prefix = attribute_prefix(name);
                    if last_prefix != Some(prefix) || attributes.last().is_some_and(|a| a.dim == 4) {
                        attributes.push(VertexAttribute { name: format!("vertex_{prefix}"), dim: 0, values: Vec::new() });
                    }
                    last_prefix = Some(prefix);
                    let a = attributes.len() - 1;
                    attributes[a].dim += 1;
                    Sink::Attribute(a, attributes[a].name == "vertex_color" && !matches!(ty, Scalar::F32 | Scalar::F64))
                }
            },
            Property::List { .. } => {
                last_prefix = None;
                Sink::Nowhere
            }
        };
        sinks.push(sink);
    }
    let mut present = [false; 8];
    for sink in &sinks {
        if let Sink::Slot(s) = *sink {
            present[s] = true;
        }
    }
    if !present[..3].iter().all(|&b| b) {
        return Err(Error::format(body.path, "header", "the vertex element lacks one of x, y, z"));
    }
    let has_normals = present[3..6].iter().all(|&b| b);
    let has_uvs = present[6..8].iter().all(|&b| b);
    if let Some(twice) = attributes.iter().enumerate().find(|(i, a)| attributes[..*i].iter().any(|b| b.name == a.name)) {
        return Err(Error::format(body.path, "header", format!("the vertex attribute `{}` is given twice", twice.1.name)));
    }

    let n = element.count;
    mesh.positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(if has_normals { n } else { 0 });
    let mut uvs = Vec::with_capacity(if has_uvs { n } else { 0 });
    for a in &mut attributes {
        a.values.reserve(n * a.dim);
    }
    for i in 0..n {
        let at = body.next_at();
        let mut values = [0.0f32; 8];
        for (p, sink) in element.properties.iter().zip(&sinks) {
            match p {
                Property::Scalar { ty, .. } => {
                    let value = body.read(*ty)? as f32;
                    match *sink {
                        Sink::Slot(s) => values[s] = value,
                        Sink::Attribute(a, colour) => attributes[a].values.push(if colour { value / 255.0 } else { value }),
                        Sink::Nowhere => {}
                    }
                }
                Property::List { count, item, .. } => {
                    let k = body.read_count(*count)?;
                    for _ in 0..k {
                        body.read(*item)?;
                    }
                }
            }
        }
        let position = Vec3::new(values[0], values[1], values[2]);
        if !position.is_finite() {
            return Err(Error::format(body.path, at, format!("vertex {i}: position {position} is not finite")));
        }
        mesh.positions.push(position);
        if has_normals {
            normals.push(Vec3::new(values[3], values[4], values[5]));
        }
        if has_uvs {
            uvs.push(Vec2::new(values[6], values[7]));
        }
    }
    mesh.normals = has_normals.then_some(normals);
    mesh.uvs = has_uvs.then_some(uvs);
    mesh.attributes = attributes;
    Ok(())
}

fn read_ply_faces(body: &mut PlyBody, element: &Element, mesh: &mut MeshData) -> Result<()> {
    let is_index_list = |p: &Property| matches!(p, Property::List { name, .. } if name == "vertex_indices" || name == "vertex_index");
    if !element.properties.iter().any(is_index_list) {
        return Err(Error::format(body.path, "header", "the face element lacks a `vertex_indices` list"));
    }
    mesh.indices = Vec::with_capacity(element.count);
    let mut polygon: Vec<u32> = Vec::new();
    // The vertex element usually comes first; if it does not, `validate` checks later.
    let limit = if mesh.positions.is_empty() { u32::MAX as f64 } else { mesh.positions.len() as f64 };
    for f in 0..element.count {
        for p in &element.properties {
            match p {
                Property::List { count, item, .. } if is_index_list(p) => {
                    let at = body.next_at();
                    let k = body.read_count(*count)?;
                    if k < 3 {
                        return Err(Error::format(body.path, at, format!("face {f}: {k} vertices; expected at least 3")));
                    }
                    polygon.clear();
                    for _ in 0..k {
                        let at = body.next_at();
                        let i = body.read(*item)?;
                        if !(i >= 0.0 && i < limit) {
                            return Err(Error::format(
                                body.path,
                                at,
                                format!("face {f}: vertex index {i} out of range: the mesh has {} vertices", mesh.positions.len()),
                            ));
                        }
                        polygon.push(i as u32);
                    }
                    for j in 1..k - 1 {
                        mesh.indices.push([polygon[0], polygon[j], polygon[j + 1]]);
                    }
                }
                Property::List { count, item, .. } => {
                    let k = body.read_count(*count)?;
                    for _ in 0..k {
                        body.read(*item)?;
                    }
                }
                Property::Scalar { ty, .. } => {
                    body.read(*ty)?;
                }
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------------
// Mitsuba .serialized

const SERIALIZED_ID: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const DOUBLE_PRECISION: u32 = 0x2000;
/// Deflate cannot expand data by more than about 1032:1 (a 258-byte match coded in 2 bits, RFC 1951
/// §3.2.5); a stream claiming more than this many bytes per compressed byte is lying.
const MAX_INFLATE_RATIO: usize = 1032;

/// Loads mesh number `shape_index` (0-based) of a Mitsuba `.serialized` file (layout in the module docs).
/// An index past the last mesh is an error that says how many the file holds.
pub fn load_serialized(path: &Path, shape_index: usize) -> Result<MeshData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    serialized_from_bytes(path, &bytes, shape_index)
}

/// Parses mesh number `shape_index` of the content of a `.serialized` file; `path` only names it in errors.
pub fn serialized_from_bytes(path: &Path, bytes: &[u8], shape_index: usize) -> Result<MeshData> {
    parse_serialized(path, bytes, shape_index)
}

fn le_u16(bytes: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(bytes.get(at..at + 2)?.try_into().ok()?))
}
fn le_u32(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
}
fn le_u64(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

/// Reads the u16 identifier and version at `at`; returns the version.
fn serialized_header(path: &Path, bytes: &[u8], at: usize) -> Result<u16> {
    let byte = format!("byte {at}");
    let id = le_u16(bytes, at).ok_or_else(|| Error::format(path, &byte, "truncated mesh header"))?;
    if id != SERIALIZED_ID {
        return Err(Error::format(path, &byte, format!("expected the format identifier 0x041C, found {id:#06x}")));
    }
    let version = le_u16(bytes, at + 2).ok_or_else(|| Error::format(path, &byte, "truncated mesh header"))?;
    if version != 3 && version != 4 {
        return Err(Error::format(path, format!("byte {}", at + 2), format!("expected version 3 or 4, found {version}")));
    }
    Ok(version)
}

fn parse_serialized(path: &Path, bytes: &[u8], shape_index: usize) -> Result<MeshData> {
    let version = serialized_header(path, bytes, 0)?;
    let len = bytes.len();

    // The dictionary at the end: offsets, then the u32 mesh count.
    let count_at = len.checked_sub(4).filter(|&c| c >= 4).ok_or_else(|| Error::format(path, "byte 4", "truncated file"))?;
    let count = le_u32(bytes, count_at).unwrap_or(0) as usize;
    let offset_size = if version == 4 { 8 } else { 4 };
    let dict_at =
        count.checked_mul(offset_size).and_then(|d| count_at.checked_sub(d)).filter(|&d| d >= 4 && count > 0).ok_or_else(|| {
            Error::format(path, format!("byte {count_at}"), format!("mesh count {count} does not fit the file of {len} bytes"))
        })?;
    if shape_index >= count {
        return Err(Error::format(path, "dictionary", format!("shape_index {shape_index} out of range: the file holds {count} meshes")));
    }
    let offset = |i: usize| -> Result<usize> {
        let at = dict_at + i * offset_size;
        let value = if version == 4 { le_u64(bytes, at) } else { le_u32(bytes, at).map(u64::from) };
        value
            .and_then(|v| usize::try_from(v).ok())
            .filter(|&v| v < dict_at)
            .ok_or_else(|| Error::format(path, format!("byte {at}"), format!("offset of mesh {i} lies outside the file")))
    };
    let start = offset(shape_index)?;
    let end = if shape_index + 1 < count { offset(shape_index + 1)? } else { dict_at };
    if end < start + 4 {
        return Err(Error::format(path, format!("byte {start}"), format!("mesh {shape_index} has no data")));
    }
    serialized_header(path, bytes, start)?;
    let stream_at = start + 4;
    let compressed = &bytes[stream_at..end];
    decode_serialized_mesh(path, compressed, stream_at, version, shape_index)
}

/// Decodes one mesh's zlib stream. Errors give the offset in the decompressed stream of mesh `index`.
fn decode_serialized_mesh(path: &Path, compressed: &[u8], stream_at: usize, version: u16, index: usize) -> Result<MeshData> {
    let mut z = flate2::read::ZlibDecoder::new(compressed);
    let mut decompressed = 0usize;
    let at = |offset: usize| format!("mesh {index} (stream at byte {stream_at}), decompressed byte {offset}");
    let zerr = |offset: usize, e: std::io::Error| Error::format(path, at(offset), format!("corrupt or truncated zlib stream: {e}"));

    let mut read_exact = |buf: &mut [u8], decompressed: &mut usize| -> Result<()> {
        z.read_exact(buf).map_err(|e| zerr(*decompressed, e))?;
        *decompressed += buf.len();
        Ok(())
    };
    let mut word = [0u8; 4];
    read_exact(&mut word, &mut decompressed)?;
    let flags = u32::from_le_bytes(word);
    if version == 4 {
        // The name: NUL-terminated; bounded so a stream without a NUL cannot run forever.
        let mut byte = [0u8; 1];
        for _ in 0..65_536 {
            read_exact(&mut byte, &mut decompressed)?;
            if byte[0] == 0 {
                break;
            }
        }
        if byte[0] != 0 {
            return Err(Error::format(path, at(decompressed), "mesh name longer than 64 KiB"));
        }
    }
    let mut quad = [0u8; 8];
    read_exact(&mut quad, &mut decompressed)?;
    let vertex_count = u64::from_le_bytes(quad);
    read_exact(&mut quad, &mut decompressed)?;
    let triangle_count = u64::from_le_bytes(quad);

    let float = if flags & DOUBLE_PRECISION != 0 { 8 } else { 4 };
    let index_size = if vertex_count > u64::from(u32::MAX) { 8 } else { 4 };
    let mut floats_per_vertex = 3;
    if flags & HAS_NORMALS != 0 {
        floats_per_vertex += 3;
    }
    if flags & HAS_TEXCOORDS != 0 {
        floats_per_vertex += 2;
    }
    if flags & HAS_COLORS != 0 {
        floats_per_vertex += 3;
    }
    // Check the counts against what the compressed bytes can possibly hold before allocating.
    let needed = usize::try_from(vertex_count)
        .ok()
        .and_then(|v| v.checked_mul(floats_per_vertex * float))
        .zip(usize::try_from(triangle_count).ok().and_then(|t| t.checked_mul(3 * index_size)))
        .and_then(|(a, b)| a.checked_add(b));
    let limit = compressed.len().saturating_mul(MAX_INFLATE_RATIO);
    let needed = needed.filter(|&n| n <= limit && vertex_count <= u64::from(u32::MAX)).ok_or_else(|| {
        Error::format(
            path,
            at(decompressed - 16),
            format!("{vertex_count} vertices and {triangle_count} triangles cannot fit in {} compressed bytes", compressed.len()),
        )
    })?;
    let data_at = decompressed;
    // Grown as the stream delivers, so a stream that ends early costs only what it held.
    let mut data = Vec::new();
    let got = (&mut z).take(needed as u64).read_to_end(&mut data).map_err(|e| zerr(data_at + data.len(), e))?;
    if got < needed {
        return Err(zerr(data_at + got, std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "failed to fill whole buffer")));
    }

    let (nv, nt) = (vertex_count as usize, triangle_count as usize);
    let value = |k: usize| -> f32 {
        if float == 8 {
            f64::from_le_bytes(data[8 * k..8 * k + 8].try_into().unwrap_or([0; 8])) as f32
        } else {
            f32::from_le_bytes(data[4 * k..4 * k + 4].try_into().unwrap_or([0; 4]))
        }
    };
    let vec3s = |first: usize| -> Vec<Vec3> {
        (0..nv).map(|i| Vec3::new(value(first + 3 * i), value(first + 3 * i + 1), value(first + 3 * i + 2))).collect()
    };
    let mut next = 0; // index of the next float
    let positions = vec3s(next);
    next += 3 * nv;
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::format(path, at(data_at + 3 * float * i), format!("vertex {i}: position {} is not finite", positions[i])));
    }
    let mut normals = None;
    if flags & HAS_NORMALS != 0 {
        normals = Some(vec3s(next));
        next += 3 * nv;
    }
    let mut uvs = None;
    if flags & HAS_TEXCOORDS != 0 {
        uvs = Some((0..nv).map(|i| Vec2::new(value(next + 2 * i), value(next + 2 * i + 1))).collect());
        next += 2 * nv;
    }
    if flags & HAS_COLORS != 0 {
        next += 3 * nv;
    }
    if flags & FACE_NORMALS != 0 {
        normals = None;
    }
    let index_bytes = &data[next * float..];
    let index_at = data_at + next * float;
    let mut indices = Vec::with_capacity(nt);
    for t in 0..nt {
        let mut tri = [0u32; 3];
        for (c, slot) in tri.iter_mut().enumerate() {
            let k = 3 * t + c;
            let i = if index_size == 8 {
                u64::from_le_bytes(index_bytes[8 * k..8 * k + 8].try_into().unwrap_or([0xff; 8]))
            } else {
                u64::from(u32::from_le_bytes(index_bytes[4 * k..4 * k + 4].try_into().unwrap_or([0xff; 4])))
            };
            if i >= vertex_count {
                return Err(Error::format(
                    path,
                    at(index_at + index_size * k),
                    format!("face {t}: vertex index {i} out of range: the mesh has {vertex_count} vertices"),
                ));
            }
            *slot = i as u32;
        }
        indices.push(tri);
    }
    let mesh = MeshData { positions, normals, uvs, indices, attributes: Vec::new() };
    mesh.validate(path)?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MESHES: &str = "/work/shared/data/mitsuba/common/meshes";

    fn scratch(name: &str, contents: &[u8]) -> crate::scratch::ScratchFile {
        crate::scratch::ScratchFile::new(name, contents)
    }

    fn assert_format_error(result: Result<MeshData>, needles: &[&str]) {
        let err = result.expect_err("malformed mesh accepted");
        let text = err.to_string();
        assert!(matches!(err, Error::Format { .. }), "{text}");
        for needle in needles {
            assert!(text.contains(needle), "`{text}` lacks `{needle}`");
        }
    }

    /// Radius statistics of a mesh about the origin, and the range of normal lengths.
    fn sphere_stats(mesh: &MeshData) -> (f32, f32) {
        let (lo, hi) = mesh.positions.iter().fold((f32::MAX, 0.0f32), |(lo, hi), p| (lo.min(p.length()), hi.max(p.length())));
        (lo, hi)
    }

    #[test]
    fn obj_sphere_lies_on_the_unit_sphere() {
        let path = Path::new(MESHES).join("sphere.obj");
        let mesh = load_obj(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let faces = text.lines().filter(|l| l.starts_with("f ")).collect::<Vec<_>>();
        let triangles: usize = faces.iter().map(|l| l.split_whitespace().count() - 3).sum();
        assert_eq!(mesh.indices.len(), triangles);
        let (lo, hi) = sphere_stats(&mesh);
        assert!(lo > 0.99 && hi < 1.01, "radius in [{lo}, {hi}]");
        let normals = mesh.normals.as_ref().expect("sphere.obj has normals");
        assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
        // Smooth sphere: each normal points along its position.
        assert!(mesh.positions.iter().zip(normals).all(|(p, n)| p.normalize().dot(*n) > 0.99));
        assert!(mesh.uvs.is_some());
        println!(
            "sphere.obj: {} triangles, {} vertices after de-duplication, radius [{lo}, {hi}]",
            mesh.indices.len(),
            mesh.positions.len()
        );
    }

    #[test]
    fn obj_rectangle_and_cornell_box() {
        let rect = load_obj(&Path::new(MESHES).join("rectangle.obj")).unwrap();
        assert_eq!(rect.indices.len(), 2);
        let mut flipped = rect.clone();
        flipped.flip_tex_coords();
        assert_eq!(flipped.uvs.as_ref().unwrap()[1], Vec2::new(0.0, 1.0));
        assert_eq!(rect.positions.len(), 4);
        assert!(rect.normals.is_none() && rect.uvs.is_some());
        let mut names: Vec<_> = std::fs::read_dir(Path::new(MESHES).join("cbox")).unwrap().map(|e| e.unwrap().path()).collect();
        names.sort();
        for path in names.iter().filter(|p| p.extension().is_some_and(|e| e == "obj")) {
            let mesh = load_obj(path).unwrap();
            assert!(!mesh.indices.is_empty());
            println!(
                "{}: {} triangles, {} vertices",
                path.file_name().unwrap().to_string_lossy(),
                mesh.indices.len(),
                mesh.positions.len()
            );
        }
    }

    #[test]
    fn ply_sphere_matches_its_header() {
        let mesh = load_ply(&Path::new(MESHES).join("sphere.ply")).unwrap();
        assert_eq!(mesh.positions.len(), 422);
        assert!(mesh.indices.len() >= 840);
        let (lo, hi) = sphere_stats(&mesh);
        println!("sphere.ply: {} vertices, {} triangles, radius [{lo}, {hi}]", mesh.positions.len(), mesh.indices.len());
        // Integer coordinates on a sphere of radius ~127 (a different, coarser tessellation than
        // sphere.obj): within 2 % of the mean radius.
        let mid = 0.5 * (lo + hi);
        assert!((hi - lo) / mid < 0.04 && (120.0..135.0).contains(&mid), "radius in [{lo}, {hi}]");
    }

    #[test]
    fn serialized_matpreview_all_meshes() {
        let path = Path::new(MESHES).join("matpreview.serialized");
        let mut counts = Vec::new();
        for i in 0.. {
            match load_serialized(&path, i) {
                Ok(mesh) => {
                    assert!(!mesh.indices.is_empty());
                    if let Some(n) = &mesh.normals {
                        assert!(n.iter().all(|n| (n.length() - 1.0).abs() < 1e-2), "mesh {i} normals not unit");
                    }
                    counts.push((mesh.positions.len(), mesh.indices.len(), mesh.normals.is_some(), mesh.uvs.is_some()));
                }
                Err(e) => {
                    assert!(e.to_string().contains("out of range"), "{e}");
                    break;
                }
            }
        }
        println!("matpreview.serialized: {} meshes (vertices, triangles, normals, uvs): {counts:?}", counts.len());
        assert_eq!(counts.len(), 3);
    }

    #[test]
    fn scenes_folder_meshes_load() {
        let root = Path::new("/work/shared/data/mitsuba/scenes");
        let mut stack = vec![root.to_path_buf()];
        while let Some(dir) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else { continue };
            for entry in entries {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                match path.extension().and_then(|e| e.to_str()) {
                    Some("ply") => {
                        let m = load_ply(&path).unwrap();
                        println!("{}: {} triangles", path.display(), m.indices.len());
                    }
                    Some("obj") => {
                        let m = load_obj(&path).unwrap();
                        println!("{}: {} triangles", path.display(), m.indices.len());
                    }
                    Some("serialized") => {
                        let mut i = 0;
                        while let Ok(m) = load_serialized(&path, i) {
                            println!("{} [{i}]: {} triangles", path.display(), m.indices.len());
                            i += 1;
                        }
                        assert!(i > 0, "{}", path.display());
                    }
                    _ => {}
                }
            }
        }
    }

    /// Further vertex properties become attributes grouped as Mitsuba groups them: `color_0..2` into
    /// `vertex_color`, `n_x n_y` into `vertex_n`, a lone name into its own; 8-bit bare colours / 255.
    #[test]
    fn ply_vertex_attributes_are_grouped_by_prefix() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                    property float color_0\nproperty float color_1\nproperty float color_2\nproperty float quality\n\
                    property float n_x\nproperty float n_y\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
                    0 0 0 0.1 0.2 0.3 5 1 2\n1 0 0 0.4 0.5 0.6 6 3 4\n0 1 0 0.7 0.8 0.9 7 5 6\n3 0 1 2\n";
        let mesh = ply_from_bytes(Path::new("a.ply"), text.as_bytes()).unwrap();
        let names: Vec<(&str, usize)> = mesh.attributes.iter().map(|a| (a.name.as_str(), a.dim)).collect();
        assert_eq!(names, vec![("vertex_color", 3), ("vertex_quality", 1), ("vertex_n", 2)]);
        assert_eq!(mesh.attributes[0].values, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]);
        assert_eq!(mesh.attributes[2].values, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                    property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n\
                    property list uchar int vertex_indices\nend_header\n0 0 0 255 0 51\n1 0 0 0 0 0\n0 1 0 0 0 0\n3 0 1 2\n";
        let mesh = ply_from_bytes(Path::new("b.ply"), text.as_bytes()).unwrap();
        assert_eq!(mesh.attributes[0].name, "vertex_color");
        assert_eq!(&mesh.attributes[0].values[..3], &[1.0, 0.0, 0.2]);
    }

    #[test]
    fn obj_index_forms_and_negative_indices() {
        let text = "# quad with every corner form\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                    vn 0 0 1\ng quad\nusemtl m\ns off\nf -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1\nf 1/1/1 3/3/1 4/4/1 # reuses corners\n";
        let mesh = load_obj(&scratch("forms.obj", text.as_bytes())).unwrap();
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.uvs.as_ref().unwrap()[2], Vec2::new(1.0, 1.0));
        assert_eq!(mesh.normals.as_ref().unwrap()[3], Vec3::Z);
        // v//vn and plain v.
        let mesh = load_obj(&scratch("n.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1 2 3\n")).unwrap();
        assert_eq!(mesh.positions.len(), 6);
        assert!(mesh.normals.is_none(), "mixed faces: not every corner has a normal");
        // Same position with different normals → distinct vertices.
        let mesh = load_obj(&scratch("split.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n"))
            .unwrap();
        assert_eq!(mesh.positions.len(), 6);
        assert_eq!(mesh.normals.unwrap()[3], -Vec3::Z);
    }

    #[test]
    fn obj_malformed_files_are_errors() {
        assert_format_error(
            load_obj(&scratch("bad1.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")),
            &["bad1.obj", "line 4", "out of range"],
        );
        assert_format_error(load_obj(&scratch("bad2.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")), &["line 4"]);
        assert_format_error(load_obj(&scratch("bad3.obj", b"v 0 0 nan\n")), &["line 1", "not finite"]);
        assert_format_error(load_obj(&scratch("bad4.obj", b"v 0 0\n")), &["line 1"]);
        assert_format_error(load_obj(&scratch("bad5.obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n")), &["line 3", "at least 3"]);
        assert_format_error(load_obj(&scratch("bad6.obj", b"v 0 0 0\nf 1/x/1 1 1\n")), &["line 2"]);
        assert_format_error(load_obj(&scratch("bad7.obj", b"v 0 0 0\nf 1/1 1 1\n")), &["texture index 1 out of range"]);
        // Truncated real file: the cut lands mid-line, which is either an error or a smaller valid mesh.
        let bytes = std::fs::read(Path::new(MESHES).join("sphere.obj")).unwrap();
        for len in [100, 1000, bytes.len() / 2] {
            let _ = load_obj(&scratch("trunc.obj", &bytes[..len]));
        }
    }

    const ASCII_PLY: &str = "ply\nformat ascii 1.0\ncomment a unit quad\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nproperty uchar red\nproperty float s\nproperty float t\nelement face 1\n\
        property list uchar int vertex_indices\nproperty int flags\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n\
        0 0 0 255 0 0\n1 0 0 255 1 0\n1 1 0 255 1 1\n0 1 0 255 0 1\n4 0 1 2 3 7\n0 1\n";

    /// The same quad as a binary PLY in either byte order, with normals and a ushort-counted list.
    fn binary_ply(big_endian: bool) -> Vec<u8> {
        let order = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
        let mut out = format!(
            "ply\nformat {order} 1.0\nelement vertex 4\nproperty double x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty short junk\nelement face 1\n\
             property list ushort uint vertex_index\nend_header\n"
        )
        .into_bytes();
        let put = |out: &mut Vec<u8>, le: &[u8]| {
            let mut b = le.to_vec();
            if big_endian {
                b.reverse();
            }
            out.extend_from_slice(&b);
        };
        for (x, y) in [(0.0f64, 0.0f32), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            put(&mut out, &x.to_le_bytes());
            put(&mut out, &y.to_le_bytes());
            put(&mut out, &0.0f32.to_le_bytes());
            for n in [0.0f32, 0.0, 1.0] {
                put(&mut out, &n.to_le_bytes());
            }
            put(&mut out, &(-7i16).to_le_bytes());
        }
        put(&mut out, &4u16.to_le_bytes());
        for i in 0..4u32 {
            put(&mut out, &i.to_le_bytes());
        }
        out
    }

    #[test]
    fn ply_ascii_and_binary_agree() {
        let ascii = load_ply(&scratch("quad.ply", ASCII_PLY.as_bytes())).unwrap();
        assert_eq!(ascii.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(ascii.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(ascii.uvs.as_ref().unwrap()[1], Vec2::new(1.0, 0.0));
        assert!(ascii.normals.is_none());
        for big in [false, true] {
            let mesh = load_ply(&scratch("quad_bin.ply", &binary_ply(big))).unwrap();
            assert_eq!(mesh.positions, ascii.positions, "big endian: {big}");
            assert_eq!(mesh.indices, ascii.indices);
            assert!(mesh.normals.unwrap().iter().all(|n| *n == Vec3::Z));
        }
    }

    #[test]
    fn ply_malformed_files_are_errors() {
        let bad_index = ASCII_PLY.replace("4 0 1 2 3 7", "4 0 1 2 9 7");
        assert_format_error(load_ply(&scratch("idx.ply", bad_index.as_bytes())), &["idx.ply", "face 0", "out of range"]);
        let huge = ASCII_PLY.replace("element vertex 4", "element vertex 4000000000000");
        assert_format_error(load_ply(&scratch("huge.ply", huge.as_bytes())), &["huge.ply", "more than"]);
        let nan = ASCII_PLY.replace("1 1 0 255 1 1", "1 nan 0 255 1 1");
        assert_format_error(load_ply(&scratch("nan.ply", nan.as_bytes())), &["line 20", "not finite"]);
        let short = ASCII_PLY.replace("4 0 1 2 3 7", "2 0 1 7");
        assert_format_error(load_ply(&scratch("short.ply", short.as_bytes())), &["face 0"]);
        assert_format_error(load_ply(&scratch("magic.ply", b"plx\n")), &["line 1"]);
        // Binary: a face list claiming 65535 entries in a short file, and every truncation of the file.
        let mut bin = binary_ply(false);
        let n = bin.len();
        bin[n - 18] = 0xff;
        bin[n - 17] = 0xff;
        assert_format_error(load_ply(&scratch("long.ply", &bin)), &["long.ply", "byte"]);
        let bin = binary_ply(true);
        for len in 0..bin.len() {
            assert!(load_ply(&scratch("cut.ply", &bin[..len])).is_err(), "truncated to {len} bytes accepted");
        }
        let huge = String::from_utf8_lossy(&binary_ply(false)).replace("element face 1", "element face 99999999999");
        let mut bytes = binary_ply(false);
        let header_end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
        let mut patched = huge.as_bytes()[..huge.find("end_header").unwrap()].to_vec();
        patched.extend_from_slice(&bytes.split_off(header_end));
        assert_format_error(load_ply(&scratch("hugebin.ply", &patched)), &["more than"]);
        // Real file, truncated.
        let real = std::fs::read(Path::new(MESHES).join("sphere.ply")).unwrap();
        assert!(load_ply(&scratch("sphere_cut.ply", &real[..real.len() / 2])).is_err());
    }

    fn serialized_file(version: u16, vertex_count: u64, triangles: &[[u32; 3]], positions: &[f32]) -> Vec<u8> {
        use std::io::Write;
        let mut raw = Vec::new();
        raw.extend_from_slice(&0x1000u32.to_le_bytes());
        if version == 4 {
            raw.extend_from_slice(b"tri\0");
        }
        raw.extend_from_slice(&vertex_count.to_le_bytes());
        raw.extend_from_slice(&(triangles.len() as u64).to_le_bytes());
        for p in positions {
            raw.extend_from_slice(&p.to_le_bytes());
        }
        for t in triangles.iter().flatten() {
            raw.extend_from_slice(&t.to_le_bytes());
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&raw).unwrap();
        let mut out = Vec::new();
        out.extend_from_slice(&SERIALIZED_ID.to_le_bytes());
        out.extend_from_slice(&version.to_le_bytes());
        out.extend_from_slice(&z.finish().unwrap());
        if version == 4 {
            out.extend_from_slice(&0u64.to_le_bytes());
        } else {
            out.extend_from_slice(&0u32.to_le_bytes());
        }
        out.extend_from_slice(&1u32.to_le_bytes());
        out
    }

    #[test]
    fn serialized_hand_made_and_malformed() {
        let tri = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        for version in [3, 4] {
            let mesh = load_serialized(&scratch("tri.serialized", &serialized_file(version, 3, &[[0, 1, 2]], &tri)), 0).unwrap();
            assert_eq!(mesh.indices, vec![[0, 1, 2]]);
            assert_eq!(mesh.positions[1], Vec3::X);
        }
        let bad = scratch("badidx.serialized", &serialized_file(4, 3, &[[0, 1, 3]], &tri));
        assert_format_error(load_serialized(&bad, 0), &["badidx.serialized", "face 0", "out of range"]);
        let huge = scratch("huge.serialized", &serialized_file(4, 1 << 40, &[[0, 1, 2]], &tri));
        assert_format_error(load_serialized(&huge, 0), &["cannot fit"]);
        let lying = scratch("lying.serialized", &serialized_file(4, 300, &[[0, 1, 2]], &tri));
        assert_format_error(load_serialized(&lying, 0), &["zlib"]);
        let nan = scratch("nan.serialized", &serialized_file(3, 3, &[[0, 1, 2]], &[0.0, f32::NAN, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]));
        assert_format_error(load_serialized(&nan, 0), &["not finite"]);
        assert_format_error(load_serialized(&bad, 1), &["out of range", "1 meshes"]);
        // Every truncation of a real file is an error, never a panic.
        let real = std::fs::read(Path::new(MESHES).join("matpreview.serialized")).unwrap();
        for len in [0, 3, 4, 8, 100, 5000, real.len() / 2, real.len() - 1] {
            let path = scratch("cut.serialized", &real[..len]);
            assert!(load_serialized(&path, 0).is_err(), "{len}");
        }
    }
}
