//! The `tensor_file` container: named n-dimensional arrays in one little-endian file, the format Mitsuba's
//! `TensorFile` reads and the RGL material database (Dupuy & Jakob 2018) ships its `.bsdf` files in.
//!
//! # Layout (all integers little-endian)
//!
//! | bytes            | content                                                                  |
//! |------------------|--------------------------------------------------------------------------|
//! | 12               | magic `tensor_file\0`                                                    |
//! | 1 + 1            | version major, minor: `1`, `0`                                           |
//! | 4                | `u32` number of fields                                                   |
//! | per field        | `u16` name length, the name (UTF-8), `u16` rank, `u8` dtype, `u64` byte offset of the data from the start of the file, `u64` × rank shape |
//! | …                | the data of each field, C order (last index fastest), at its offset        |
//!
//! The dtype codes are those of Mitsuba's `Struct::Type`: 1 `u8`, 2 `i8`, 3 `u16`, 4 `i16`, 5 `u32`,
//! 6 `i32`, 7 `u64`, 8 `i64`, 9 `f16`, 10 `f32`, 11 `f64`.
//!
//! Mitsuba maps the file and trusts the header. gonio reads it into memory and checks every field
//! against the file before handing it out: a truncated file, a foreign file, an absurd size or rank, a
//! field that overlaps the header or runs past the end of the file, a missing field or one of the wrong
//! type, shape or with non-finite values are all [`Error::Format`]s naming the file, the byte or field
//! and what was expected.
//!
//! ```
//! use gonio::measured::tensor_file::{DType, TensorFile};
//! let bytes = gonio::measured::tensor_file::encode(&[("theta_i", DType::F32, &[2], &[0f32, 1.5].iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>())]);
//! let file = TensorFile::parse(std::path::Path::new("example.bsdf"), bytes).unwrap();
//! assert_eq!(file.f32_field("theta_i", 1).unwrap().data, vec![0.0, 1.5]);
//! assert!(file.field("phi_i").is_err());
//! ```

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The magic bytes every tensor file starts with.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";

/// Files larger than this are refused before reading (2026-11: the largest RGL file is ~10 MB; 1 GiB
/// leaves room for spectral, anisotropic tables while keeping a corrupt size from exhausting memory).
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// At most this many fields (the RGL files have 11–13).
pub const MAX_FIELDS: u32 = 4096;
/// At most this rank (the RGL files use up to 5).
pub const MAX_RANK: u16 = 16;

/// The element type of a field (Mitsuba's `Struct::Type` codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F16,
    F32,
    F64,
}

impl DType {
    /// The type of a dtype code, or `None` for an unknown code.
    #[must_use]
    pub fn from_code(code: u8) -> Option<DType> {
        use DType::*;
        Some(match code {
            1 => U8,
            2 => I8,
            3 => U16,
            4 => I16,
            5 => U32,
            6 => I32,
            7 => U64,
            8 => I64,
            9 => F16,
            10 => F32,
            11 => F64,
            _ => return None,
        })
    }

    /// The code stored in the file.
    #[must_use]
    pub fn code(self) -> u8 {
        self as u8 + 1
    }

    /// Bytes per element.
    #[must_use]
    pub fn size(self) -> usize {
        use DType::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 | F16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }

    /// The name used in messages (`f32`, `u8`, …).
    #[must_use]
    pub fn name(self) -> &'static str {
        use DType::*;
        match self {
            U8 => "u8",
            I8 => "i8",
            U16 => "u16",
            I16 => "i16",
            U32 => "u32",
            I32 => "i32",
            U64 => "u64",
            I64 => "i64",
            F16 => "f16",
            F32 => "f32",
            F64 => "f64",
        }
    }
}

/// One field of the table of contents.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: String,
    pub dtype: DType,
    pub shape: Vec<usize>,
    /// Byte offset of the data from the start of the file.
    pub offset: usize,
}

impl Field {
    /// Number of elements (the product of the shape; 1 for rank 0).
    #[must_use]
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Whether the field has no elements.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn shape_text(&self) -> String {
        format!("[{}]", self.shape.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "))
    }
}

/// A field read as `f32` values, with its shape.
#[derive(Clone, Debug, PartialEq)]
pub struct F32Array {
    pub shape: Vec<usize>,
    pub data: Vec<f32>,
}

/// A parsed tensor file: its table of contents and its bytes.
#[derive(Clone, Debug)]
pub struct TensorFile {
    path: PathBuf,
    bytes: Vec<u8>,
    fields: Vec<Field>,
}

/// A cursor over the header that reports truncation with the byte it needed.
struct Reader<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or_else(|| {
            Error::format(
                self.path,
                format!("byte {}", self.pos),
                format!("truncated tensor file: {what} needs {n} bytes, the file has {} bytes in all", self.bytes.len()),
            )
        })?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.take(1, what)?[0])
    }

    fn u16(&mut self, what: &str) -> Result<u16> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self, what: &str) -> Result<u32> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    fn u64(&mut self, what: &str) -> Result<u64> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

impl TensorFile {
    /// Read and parse the tensor file at `path`.
    pub fn open(path: &Path) -> Result<TensorFile> {
        let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
        if meta.len() > MAX_FILE_BYTES {
            return Err(Error::format(
                path,
                "file size",
                format!("{} bytes is larger than the {} bytes a tensor file may have", meta.len(), MAX_FILE_BYTES),
            ));
        }
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        TensorFile::parse(path, bytes)
    }

    /// Parse `bytes` (the content of `path`, which names the file in errors).
    pub fn parse(path: &Path, bytes: Vec<u8>) -> Result<TensorFile> {
        let mut r = Reader { path, bytes: &bytes, pos: 0 };
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            let start = String::from_utf8_lossy(&bytes[..bytes.len().min(12)]).escape_debug().to_string();
            return Err(Error::format(path, "byte 0", format!("not a tensor file: expected the magic `tensor_file\\0`, found `{start}`")));
        }
        r.pos = MAGIC.len();
        let (major, minor) = (r.u8("the version")?, r.u8("the version")?);
        if (major, minor) != (1, 0) {
            return Err(Error::format(path, "byte 12", format!("unsupported tensor file version {major}.{minor}; expected 1.0")));
        }
        let n_fields = r.u32("the field count")?;
        if n_fields > MAX_FIELDS {
            return Err(Error::format(path, "byte 14", format!("{n_fields} fields is more than the {MAX_FIELDS} a tensor file may have")));
        }
        let mut fields: Vec<Field> = Vec::with_capacity(n_fields as usize);
        for k in 0..n_fields {
            let at = r.pos;
            let what = format!("field {k} of {n_fields} in the table of contents");
            let name_len = r.u16(&what)? as usize;
            let name = std::str::from_utf8(r.take(name_len, &what)?)
                .map_err(|_| Error::format(path, format!("byte {at}"), format!("the name of field {k} is not UTF-8")))?
                .to_string();
            let rank = r.u16(&what)?;
            let code = r.u8(&what)?;
            let offset = r.u64(&what)?;
            let field_at = format!("field `{name}` (byte {at})");
            if rank > MAX_RANK {
                return Err(Error::format(path, field_at, format!("rank {rank} is more than the {MAX_RANK} a field may have")));
            }
            let dtype = DType::from_code(code)
                .ok_or_else(|| Error::format(path, &field_at, format!("unknown dtype code {code}; expected 1 (u8) … 11 (f64)")))?;
            let mut shape = Vec::with_capacity(rank as usize);
            let mut elements: u64 = 1;
            for _ in 0..rank {
                let n = r.u64(&what)?;
                elements = elements.saturating_mul(n);
                shape.push(n);
            }
            // Every size check in u64 before converting: a corrupt shape must not overflow usize.
            let data_bytes = elements.saturating_mul(dtype.size() as u64);
            let end = offset.saturating_add(data_bytes);
            if end > bytes.len() as u64 {
                return Err(Error::format(
                    path,
                    field_at,
                    format!(
                        "{} data of shape [{}] ({data_bytes} bytes at byte {offset}) runs past the end of the file ({} bytes): truncated?",
                        dtype.name(),
                        shape.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "),
                        bytes.len()
                    ),
                ));
            }
            if fields.iter().any(|f| f.name == name) {
                return Err(Error::format(path, field_at, "the field appears twice in the table of contents"));
            }
            fields.push(Field { name, dtype, shape: shape.iter().map(|&n| n as usize).collect(), offset: offset as usize });
        }
        // Data may not overlap the table of contents.
        let header_end = r.pos;
        if let Some(f) = fields.iter().find(|f| !f.is_empty() && f.offset < header_end) {
            return Err(Error::format(
                path,
                format!("field `{}`", f.name),
                format!("its data starts at byte {}, inside the table of contents (which ends at byte {header_end})", f.offset),
            ));
        }
        Ok(TensorFile { path: path.to_path_buf(), bytes, fields })
    }

    /// The file this was read from.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Every field, in the order of the table of contents.
    #[must_use]
    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// Whether the file has a field `name`.
    #[must_use]
    pub fn has_field(&self, name: &str) -> bool {
        self.fields.iter().any(|f| f.name == name)
    }

    /// The field `name`, or an error listing the fields the file has.
    pub fn field(&self, name: &str) -> Result<&Field> {
        self.fields.iter().find(|f| f.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.fields.iter().map(|f| f.name.as_str()).collect();
            Error::format(&self.path, format!("field `{name}`"), format!("missing; the file has the fields: {}", names.join(", ")))
        })
    }

    /// An error about field `name`.
    pub fn error(&self, name: &str, message: impl Into<String>) -> Error {
        Error::format(&self.path, format!("field `{name}`"), message)
    }

    fn raw(&self, f: &Field) -> &[u8] {
        &self.bytes[f.offset..f.offset + f.len() * f.dtype.size()]
    }

    /// The data of field `name` as stored: little-endian bytes, C order (to copy a field into another
    /// file with [`encode`]).
    pub fn field_bytes(&self, name: &str) -> Result<&[u8]> {
        Ok(self.raw(self.field(name)?))
    }

    /// The raw bytes of a `u8` field of rank `rank`.
    pub fn u8_field(&self, name: &str, rank: usize) -> Result<&[u8]> {
        let f = self.field(name)?;
        self.expect(f, DType::U8, rank)?;
        Ok(self.raw(f))
    }

    /// A `f32` field of rank `rank`, every value finite.
    pub fn f32_field(&self, name: &str, rank: usize) -> Result<F32Array> {
        let f = self.field(name)?;
        self.expect(f, DType::F32, rank)?;
        let data: Vec<f32> = self.raw(f).chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(self.error(name, format!("element {} is {}; every value must be finite", index_text(&f.shape, i), data[i])));
        }
        Ok(F32Array { shape: f.shape.clone(), data })
    }

    fn expect(&self, f: &Field, dtype: DType, rank: usize) -> Result<()> {
        if f.dtype != dtype || f.shape.len() != rank {
            return Err(self.error(
                &f.name,
                format!(
                    "expected a {}-dimensional {} array, found a {}-dimensional {} array of shape {}",
                    rank,
                    dtype.name(),
                    f.shape.len(),
                    f.dtype.name(),
                    f.shape_text()
                ),
            ));
        }
        Ok(())
    }
}

/// The multi-index `[i, j, …]` of flat index `flat` in an array of `shape` (C order).
fn index_text(shape: &[usize], mut flat: usize) -> String {
    let mut idx = vec![0; shape.len()];
    for (d, &n) in shape.iter().enumerate().rev() {
        if n > 0 {
            idx[d] = flat % n;
            flat /= n;
        }
    }
    format!("[{}]", idx.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "))
}

/// Encode fields `(name, dtype, shape, little-endian data)` as a tensor file, each field's data 8-byte
/// aligned. For tests and for writing small tables; `data` must hold exactly the shape's elements.
#[must_use]
pub fn encode(fields: &[(&str, DType, &[usize], &[u8])]) -> Vec<u8> {
    let header_len: usize = 18 + fields.iter().map(|(name, _, shape, _)| 2 + name.len() + 2 + 1 + 8 + 8 * shape.len()).sum::<usize>();
    let align = |n: usize| n.div_ceil(8) * 8;
    let mut offset = align(header_len);
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    let mut offsets = Vec::new();
    for (name, dtype, shape, data) in fields {
        debug_assert_eq!(data.len(), shape.iter().product::<usize>() * dtype.size(), "encode: field `{name}` has the wrong byte count");
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&(shape.len() as u16).to_le_bytes());
        out.push(dtype.code());
        out.extend_from_slice(&(offset as u64).to_le_bytes());
        for &n in *shape {
            out.extend_from_slice(&(n as u64).to_le_bytes());
        }
        offsets.push(offset);
        offset = align(offset + data.len());
    }
    for ((_, _, _, data), off) in fields.iter().zip(offsets) {
        out.resize(off, 0);
        out.extend_from_slice(data);
    }
    out
}

/// Little-endian bytes of `f32` values, for [`encode`].
#[must_use]
pub fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_file() -> Vec<u8> {
        let grid = f32_bytes(&[0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
        encode(&[
            ("description", DType::U8, &[5], b"hello"),
            ("grid", DType::F32, &[2, 3], &grid),
            ("flag", DType::U8, &[1], &[1]),
            ("wide", DType::F64, &[1], &2.0f64.to_le_bytes()),
        ])
    }

    fn parse(bytes: Vec<u8>) -> Result<TensorFile> {
        TensorFile::parse(Path::new("synthetic.bsdf"), bytes)
    }

    fn message(r: Result<TensorFile>) -> String {
        r.expect_err("must fail").to_string()
    }

    #[test]
    fn reads_a_synthetic_file() {
        let f = parse(sample_file()).unwrap();
        assert_eq!(f.fields().len(), 4);
        assert_eq!(f.u8_field("description", 1).unwrap(), b"hello");
        let g = f.f32_field("grid", 2).unwrap();
        assert_eq!(g.shape, vec![2, 3]);
        assert_eq!(g.data, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
        assert_eq!(f.field("wide").unwrap().dtype, DType::F64);
        // Data are 8-byte aligned as Mitsuba's writer does.
        assert!(f.fields().iter().all(|x| x.offset % 8 == 0));
    }

    #[test]
    fn wrong_magic_version_and_dtype_are_named() {
        let mut b = sample_file();
        b[0] = b'T';
        let m = message(parse(b));
        assert!(m.contains("synthetic.bsdf") && m.contains("not a tensor file"), "{m}");
        let mut b = sample_file();
        b[12] = 2;
        assert!(message(parse(b)).contains("version 2.0"));
        // dtype byte of the first field: 18 + 2 + len("description") + 2.
        let mut b = sample_file();
        b[18 + 2 + 11 + 2] = 42;
        let m = message(parse(b));
        assert!(m.contains("field `description`") && m.contains("unknown dtype code 42"), "{m}");
        assert!(message(parse(b"PK\x03\x04 a zip file".to_vec())).contains("not a tensor file"));
        assert!(message(parse(Vec::new())).contains("not a tensor file"));
    }

    #[test]
    fn truncation_anywhere_is_an_error_never_a_panic() {
        let full = sample_file();
        for len in 0..full.len() {
            let r = parse(full[..len].to_vec());
            let m = message(r);
            assert!(m.contains("synthetic.bsdf"), "{m}");
            assert!(m.contains("truncated") || m.contains("not a tensor file"), "at {len}: {m}");
        }
        assert!(parse(full).is_ok());
    }

    #[test]
    fn absurd_sizes_are_refused() {
        // A shape whose byte count overflows u64.
        let mut b = encode(&[("x", DType::F32, &[1], &f32_bytes(&[1.0]))]);
        let shape_at = 18 + 2 + 1 + 2 + 1 + 8;
        b[shape_at..shape_at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
        let m = message(parse(b));
        assert!(m.contains("runs past the end"), "{m}");
        // A field count far beyond anything real.
        let mut b = sample_file();
        b[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(message(parse(b)).contains("more than the"));
        // Data pointing into the header.
        let mut b = encode(&[("x", DType::F32, &[1], &f32_bytes(&[1.0]))]);
        b[18 + 2 + 1 + 2 + 1..18 + 2 + 1 + 2 + 1 + 8].copy_from_slice(&4u64.to_le_bytes());
        assert!(message(parse(b)).contains("inside the table of contents"));
    }

    #[test]
    fn missing_field_wrong_type_and_nan_are_named() {
        let f = parse(sample_file()).unwrap();
        let m = f.field("vndf").unwrap_err().to_string();
        assert!(m.contains("field `vndf`") && m.contains("missing") && m.contains("description, grid, flag, wide"), "{m}");
        let m = f.f32_field("description", 1).unwrap_err().to_string();
        assert!(m.contains("expected a 1-dimensional f32 array, found a 1-dimensional u8 array of shape [5]"), "{m}");
        let m = f.f32_field("grid", 3).unwrap_err().to_string();
        assert!(m.contains("expected a 3-dimensional f32"), "{m}");
        let grid = f32_bytes(&[0.0, 0.5, 1.0, 1.5, f32::NAN, 2.5]);
        let f = parse(encode(&[("grid", DType::F32, &[2, 3], &grid)])).unwrap();
        let m = f.f32_field("grid", 2).unwrap_err().to_string();
        assert!(m.contains("element [1, 1] is NaN"), "{m}");
    }
}
