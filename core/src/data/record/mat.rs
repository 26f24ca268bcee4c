//! Records as MATLAB `.mat` files (level 5: MATLAB's `-v6` and `-v7` formats).
//!
//! Each signal is a numeric vector variable (row or column) named like the CSV column.
//! Double, single and integer classes are read and converted to `f64`. Limits of the
//! `matfile` reader, turned into clear errors: v4 and v7.3 (HDF5) files cannot be read; an
//! `int32` variable anywhere in the file makes the whole file unreadable; `char`, `struct` and
//! `cell` variables are invisible. Rows in errors are the 1-based element of the vector.
//! The layout's names, units, offsets, rest stretch, rate and calibration apply as to a CSV
//! file; its text settings (separator, decimal mark, skipped lines, header) do not. The file
//! is read up to `max_bytes`, and its compressed variables inflated up to the same cap
//! (`mat_inflate`).

use super::layout::{self, Raw};
use super::{Column, ReadOptions, Record, RecordError, Signal};
use std::path::Path;

const SAVE_HINT: &str = "save the signals as double vectors with `save(file, ..., '-v7')`";

/// Read a record from a `.mat` file.
pub(super) fn read(path: &Path, opts: &ReadOptions) -> Result<Record, RecordError> {
    let source = path.display().to_string();
    let bytes = crate::data::bounded::read_file(path, opts.max_bytes).map_err(|e| match e {
        crate::data::bounded::BoundedError::Io(e) => {
            RecordError::new(&source, format!("cannot open: {e}"))
        }
        too_large => RecordError::new(&source, format!("{too_large} for a record (`max_bytes`)")),
    })?;
    read_bytes(&bytes, &source, opts)
}

/// Read a record from the bytes of a `.mat` file; `source` names it in errors.
pub(super) fn read_bytes(
    bytes: &[u8],
    source: &str,
    opts: &ReadOptions,
) -> Result<Record, RecordError> {
    check_header(source, bytes)?;
    let bytes = super::mat_inflate::inflate(bytes, source, opts.max_bytes)?;
    let file = matfile::MatFile::parse(&bytes[..]).map_err(|e| {
        RecordError::new(
            source,
            format!(
                "cannot parse the .mat file ({e}); the reader handles numeric double, single \
                 and (u)int8/16 arrays, and a single int32 variable makes the whole file \
                 unreadable: {SAVE_HINT}"
            ),
        )
    })?;
    let mut raw: Raw = Default::default();
    let mut labels = Signal::ALL.map(|s| s.name().to_string());
    for (signal, ch) in opts.wanted() {
        let name = match &ch.column {
            Column::Name(name) => name,
            Column::Number(k) => {
                return Err(RecordError::new(
                    source,
                    format!(
                        "`{signal}` is given as column {k}: a .mat file names its variables, \
                         so give the variable's name"
                    ),
                )
                .in_column(k.to_string()))
            }
        };
        labels[signal.index()].clone_from(name);
        raw[signal.index()] = vector(source, &file, name)?;
        if opts.needs(signal) && raw[signal.index()].is_none() {
            return Err(missing(source, &file, name));
        }
    }
    let raw = layout::apply(opts, raw, source, &labels, &|i| i + 1)?;
    super::into_record(raw, source, &labels, &|i| i + 1)
}

/// The variable `name` is not in the file (or not readable).
fn missing(source: &str, file: &matfile::MatFile, name: &str) -> RecordError {
    let known: Vec<&str> = file.arrays().iter().map(|a| a.name()).collect();
    RecordError::new(
        source,
        format!(
            "missing variable `{name}`; numeric variables in the file: {} \
             (char, struct and cell variables are not read: {SAVE_HINT})",
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        ),
    )
    .in_column(name)
}

/// Recognise v4 and v7.3 files before the parser fails on them obscurely.
fn check_header(source: &str, bytes: &[u8]) -> Result<(), RecordError> {
    let not_v5 = |what: &str| {
        RecordError::new(
            source,
            format!("{what}; only MATLAB level-5 files (-v6, -v7) are read: {SAVE_HINT}"),
        )
    };
    if bytes.len() < 128 {
        return Err(not_v5("too short to be a MATLAB .mat file"));
    }
    let text = String::from_utf8_lossy(&bytes[..116]);
    let version = match &bytes[126..128] {
        b"IM" => u16::from_le_bytes([bytes[124], bytes[125]]),
        b"MI" => u16::from_be_bytes([bytes[124], bytes[125]]),
        _ => 0,
    };
    if text.starts_with("MATLAB 7.3") || version == 0x0200 {
        return Err(not_v5("a MATLAB v7.3 (HDF5) file"));
    }
    if bytes[..4].contains(&0) {
        return Err(not_v5("looks like a MATLAB v4 file"));
    }
    if !text.starts_with("MATLAB") || version != 0x0100 {
        return Err(not_v5("not a MATLAB .mat file (no level-5 header)"));
    }
    Ok(())
}

/// The variable `name` as a vector of f64, if present.
fn vector(
    source: &str,
    file: &matfile::MatFile,
    name: &str,
) -> Result<Option<Vec<f64>>, RecordError> {
    let Some(array) = file.find_by_name(name) else {
        return Ok(None);
    };
    let err = |message: String| RecordError::new(source, message).in_column(name);
    let size = array.size();
    if size.iter().filter(|&&d| d > 1).count() > 1 {
        let dims: Vec<String> = size.iter().map(usize::to_string).collect();
        return Err(err(format!(
            "is a {} array, not a vector: store one signal per variable",
            dims.join("×")
        )));
    }
    use matfile::NumericData as D;
    fn widen<T: Copy + Into<f64>>(v: &[T]) -> Vec<f64> {
        v.iter().map(|&x| x.into()).collect()
    }
    let (values, complex) = match array.data() {
        D::Double { real, imag } => (real.clone(), imag.is_some()),
        D::Single { real, imag } => (widen(real), imag.is_some()),
        D::Int8 { real, imag } => (widen(real), imag.is_some()),
        D::UInt8 { real, imag } => (widen(real), imag.is_some()),
        D::Int16 { real, imag } => (widen(real), imag.is_some()),
        D::UInt16 { real, imag } => (widen(real), imag.is_some()),
        D::Int32 { real, imag } => (widen(real), imag.is_some()),
        D::UInt32 { real, imag } => (widen(real), imag.is_some()),
        D::Int64 { real, imag } => (real.iter().map(|&x| x as f64).collect(), imag.is_some()),
        D::UInt64 { real, imag } => (real.iter().map(|&x| x as f64).collect(), imag.is_some()),
    };
    if complex {
        return Err(err("is complex; a signal must be real".into()));
    }
    Ok(Some(values))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
pub(super) mod tests {
    use super::*;

    /// MATLAB array classes used by the generator.
    #[derive(Clone, Copy)]
    pub enum Class {
        Double,
        Int32,
        Char,
    }

    /// One variable for [`mat_v5`].
    pub struct Var<'a> {
        pub name: &'a str,
        pub dims: [i32; 2],
        pub values: &'a [f64],
        pub class: Class,
    }

    fn element(out: &mut Vec<u8>, data_type: u32, payload: &[u8]) {
        if payload.len() <= 4 {
            // Small data element format: type and size share the tag, data in 4 bytes.
            out.extend_from_slice(&(data_type | ((payload.len() as u32) << 16)).to_le_bytes());
            out.extend_from_slice(payload);
            out.extend(std::iter::repeat_n(0u8, 4 - payload.len()));
        } else {
            out.extend_from_slice(&data_type.to_le_bytes());
            out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
            out.extend_from_slice(payload);
            out.extend(std::iter::repeat_n(0u8, (8 - payload.len() % 8) % 8));
        }
    }

    /// A minimal little-endian level-5 MAT file: a 128-byte header, then one uncompressed
    /// miMATRIX element per variable (array flags, dimensions, name, real part).
    pub fn mat_v5(vars: &[Var]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut text = b"MATLAB 5.0 MAT-file, written by stf-core tests".to_vec();
        text.resize(116, b' ');
        out.extend_from_slice(&text);
        out.extend_from_slice(&[0u8; 8]);
        out.extend_from_slice(&0x0100u16.to_le_bytes());
        out.extend_from_slice(b"IM");
        for v in vars {
            let mut body = Vec::new();
            let class_code: u32 = match v.class {
                Class::Double => 6,
                Class::Int32 => 12,
                Class::Char => 4,
            };
            let mut flags = class_code.to_le_bytes().to_vec();
            flags.extend_from_slice(&0u32.to_le_bytes());
            element(&mut body, 6, &flags); // miUINT32
            let dims: Vec<u8> = v.dims.iter().flat_map(|d| d.to_le_bytes()).collect();
            element(&mut body, 5, &dims); // miINT32
            element(&mut body, 1, v.name.as_bytes()); // miINT8
            match v.class {
                Class::Double => {
                    let data: Vec<u8> = v.values.iter().flat_map(|x| x.to_le_bytes()).collect();
                    element(&mut body, 9, &data); // miDOUBLE
                }
                Class::Int32 => {
                    let data: Vec<u8> = v
                        .values
                        .iter()
                        .flat_map(|&x| (x as i32).to_le_bytes())
                        .collect();
                    element(&mut body, 5, &data); // miINT32
                }
                Class::Char => {
                    let data: Vec<u8> = v
                        .values
                        .iter()
                        .flat_map(|&x| (x as u16).to_le_bytes())
                        .collect();
                    element(&mut body, 4, &data); // miUINT16
                }
            }
            element(&mut out, 14, &body); // miMATRIX
        }
        out
    }

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    pub fn col<'a>(name: &'a str, values: &'a [f64], column: bool) -> Var<'a> {
        let n = values.len() as i32;
        Var {
            name,
            dims: if column { [n, 1] } else { [1, n] },
            values,
            class: Class::Double,
        }
    }

    const T: [f64; 4] = [0.0, 0.001, 0.002, 0.003];
    const X: [f64; 4] = [1e-3, 1.5e-3, -2e-3, 0.1];
    const PHI: [f64; 4] = [0.0, 0.01, 0.0201, 0.0303];
    const F: [f64; 4] = [0.1, -0.2, 0.3, 1e-9];

    #[test]
    fn same_data_as_csv_and_mat_read_identically() {
        let dir = tempfile::tempdir().unwrap();
        let bytes = mat_v5(&[
            col("t", &T, true),
            col("x", &X, false),
            col("phi", &PHI, true),
            col("f_stf", &F, false),
            col("other_signal", &F, true),
        ]);
        let mat = Record::read(&write(dir.path(), "r.mat", &bytes)).unwrap();
        let mut csv = String::from("t,x,phi,f_stf\n");
        for i in 0..4 {
            csv += &format!("{},{},{},{}\n", T[i], X[i], PHI[i], F[i]);
        }
        let csv = Record::read(&write(dir.path(), "r.csv", csv.as_bytes())).unwrap();
        assert_eq!(mat.t, csv.t);
        assert_eq!(mat.x, csv.x);
        assert_eq!(mat.phi, csv.phi);
        assert_eq!(mat.f_stf, csv.f_stf);
        assert_eq!(mat.omega, None);
        assert!(mat.source.ends_with("r.mat"));
    }

    #[test]
    fn the_layout_applies_to_mat_files() {
        use super::super::{Offset, Unit};
        let bytes = mat_v5(&[
            col("disp_mm", &[1.0, 2.0, 4.0], true),
            col("phi", &PHI[..3], true),
        ]);
        let opts = ReadOptions::default()
            .column(Signal::X, Column::Name("disp_mm".into()))
            .unit(Signal::X, Unit::Millimetre)
            .offset(Signal::X, Offset::Rest)
            .rest(0.0, 0.5)
            .rate(2.0, 0.0);
        let r = opts.read_mat_bytes(&bytes, "m.mat").unwrap();
        assert_eq!(r.t, [0.0, 0.5, 1.0]);
        assert_eq!(r.x, [-0.5e-3, 0.5e-3, 2.5e-3]);
        let e = opts
            .column(Signal::U, Column::Number(2))
            .read_mat_bytes(&bytes, "m.mat")
            .unwrap_err();
        assert!(e.message.contains("a .mat file names its variables"), "{e}");
        let e = ReadOptions::default()
            .column(Signal::FStf, Column::Name("gauge".into()))
            .read_mat_bytes(
                &mat_v5(&[
                    col("t", &T, true),
                    col("x", &X, true),
                    col("phi", &PHI, true),
                ]),
                "m.mat",
            )
            .unwrap_err();
        assert_eq!(e.column.as_deref(), Some("gauge"), "{e}");
    }

    #[test]
    fn committed_fixture_matches_its_csv_twin() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
        let mat = Record::read(&data.join("small_record.mat")).unwrap();
        let csv = Record::read(&data.join("small_record.csv")).unwrap();
        assert_eq!(mat.len(), csv.len());
        assert_eq!((mat.t, mat.x, mat.phi), (csv.t, csv.x, csv.phi));
    }

    /// `bytes` (a file from [`mat_v5`]) with every variable zlib-compressed, as `-v7` saves.
    pub fn compressed(bytes: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut out = bytes[..128].to_vec();
        let mut at = 128;
        while at < bytes.len() {
            let size = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
            let element = &bytes[at..at + 8 + size];
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
            z.write_all(element).unwrap();
            let z = z.finish().unwrap();
            out.extend_from_slice(&15u32.to_le_bytes());
            out.extend_from_slice(&(z.len() as u32).to_le_bytes());
            out.extend_from_slice(&z);
            at += 8 + size;
        }
        out
    }

    #[test]
    fn compressed_variables_read_as_the_plain_ones() {
        let plain = mat_v5(&[
            col("t", &T, true),
            col("x", &X, false),
            col("phi", &PHI, true),
            col("f_stf", &F, false),
        ]);
        let packed = compressed(&plain);
        assert!(packed[128..].starts_with(&15u32.to_le_bytes()));
        let opts = ReadOptions::default();
        let from_plain = opts.read_mat_bytes(&plain, "p.mat").unwrap();
        let from_packed = opts.read_mat_bytes(&packed, "z.mat").unwrap();
        assert_eq!(
            (from_plain.t, from_plain.x, from_plain.phi, from_plain.f_stf),
            (
                from_packed.t,
                from_packed.x,
                from_packed.phi,
                from_packed.f_stf
            )
        );
    }

    #[test]
    fn a_zlib_bomb_is_refused_at_the_inflation_cap() {
        // Three vectors of 10⁶ zeros: 24 MB once inflated, some 70 kB compressed.
        let zeros = vec![0.0; 1_000_000];
        let bomb = compressed(&mat_v5(&[
            col("t", &zeros, true),
            col("x", &zeros, true),
            col("phi", &zeros, true),
        ]));
        assert!(bomb.len() < 100_000, "{}", bomb.len());
        let capped = ReadOptions::default().max_bytes(4_000_000);
        let e = capped.read_mat_bytes(&bomb, "bomb.mat").unwrap_err();
        assert_eq!(e.file, "bomb.mat");
        assert!(
            e.message.starts_with(
                "its compressed variables inflate to more than the limit of 4000000 bytes (4.0 MB) \
                 for a record (`max_bytes`; the file itself is "
            ),
            "{e}"
        );
        // Under a cap it fits in, the file is inflated and read (its time does not increase).
        let e = ReadOptions::default()
            .read_mat_bytes(&bomb, "bomb.mat")
            .unwrap_err();
        assert!(e.message.contains("not strictly increasing"), "{e}");
        // And from disk, the file's own size is capped too.
        let dir = tempfile::tempdir().unwrap();
        let path = write(dir.path(), "bomb.mat", &bomb);
        let e = ReadOptions::default()
            .max_bytes(1000)
            .read(&path)
            .unwrap_err();
        assert!(
            e.message
                .contains("over the limit of 1000 bytes for a record"),
            "{e}"
        );
    }

    #[test]
    fn missing_variable_names_it_and_lists_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "m.mat",
            &mat_v5(&[col("t", &T, true), col("phi", &PHI, true)]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"));
        assert!(e.message.contains("variables in the file: t, phi"), "{e}");
        assert!(e.to_string().starts_with(&p.display().to_string()), "{e}");
        let p = write(
            dir.path(),
            "n.mat",
            &mat_v5(&[col("t", &T, true), col("x", &X, true)]),
        );
        let r = Record::read_mat(&p).unwrap();
        assert!(
            r.phi.is_none() && r.u.is_none(),
            "t and x alone are a record"
        );
    }

    #[test]
    fn char_variable_is_reported_as_missing_with_the_hint() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "c.mat",
            &mat_v5(&[
                col("t", &T, true),
                Var {
                    name: "x",
                    dims: [1, 4],
                    values: &[97.0, 98.0, 99.0, 100.0],
                    class: Class::Char,
                },
                col("phi", &PHI, true),
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"));
        assert!(e.message.contains("char, struct and cell"), "{e}");
    }

    #[test]
    fn int32_variable_gives_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "i.mat",
            &mat_v5(&[
                col("t", &T, true),
                col("x", &X, true),
                col("phi", &PHI, true),
                Var {
                    name: "count",
                    dims: [4, 1],
                    values: &[1.0, 2.0, 3.0, 4.0],
                    class: Class::Int32,
                },
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert!(e.message.starts_with("cannot parse"), "{e}");
        assert!(e.message.contains("int32"), "{e}");
        assert!(e.message.contains("-v7"), "{e}");
    }

    #[test]
    fn matrix_variable_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "mx.mat",
            &mat_v5(&[
                col("t", &T, true),
                Var {
                    name: "x",
                    dims: [2, 2],
                    values: &X,
                    class: Class::Double,
                },
                col("phi", &PHI, true),
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"));
        assert!(e.message.contains("2×2 array, not a vector"), "{e}");
    }

    #[test]
    fn bad_values_name_the_element_row() {
        let dir = tempfile::tempdir().unwrap();
        let mut t = T;
        t[2] = t[1];
        let p = write(
            dir.path(),
            "bt.mat",
            &mat_v5(&[
                col("t", &t, true),
                col("x", &X, true),
                col("phi", &PHI, true),
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(3), Some("t")), "{e}");
        let mut x = X;
        x[3] = f64::NAN;
        let p = write(
            dir.path(),
            "bx.mat",
            &mat_v5(&[
                col("t", &T, true),
                col("x", &x, true),
                col("phi", &PHI, true),
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(4), Some("x")), "{e}");
        let p = write(
            dir.path(),
            "len.mat",
            &mat_v5(&[
                col("t", &T, true),
                col("x", &X[..3], true),
                col("phi", &PHI, true),
            ]),
        );
        let e = Record::read_mat(&p).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"), "{e}");
        assert!(e.message.contains("same length"), "{e}");
    }

    #[test]
    fn v73_v4_and_garbage_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut v73 = mat_v5(&[col("t", &T, true)]);
        v73[..19].copy_from_slice(b"MATLAB 7.3 MAT-file");
        v73[124..126].copy_from_slice(&0x0200u16.to_le_bytes());
        let e = Record::read_mat(&write(dir.path(), "h.mat", &v73)).unwrap_err();
        assert!(
            e.message.contains("v7.3 (HDF5)") && e.message.contains("-v7"),
            "{e}"
        );
        let mut v4 = vec![0u8; 200];
        v4[4] = 1;
        let e = Record::read_mat(&write(dir.path(), "v4.mat", &v4)).unwrap_err();
        assert!(e.message.contains("v4"), "{e}");
        let e = Record::read_mat(&write(dir.path(), "s.mat", b"hello")).unwrap_err();
        assert!(e.message.contains("too short"), "{e}");
    }
}
