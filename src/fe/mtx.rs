//! Matrix Market (`.mtx`) input and output for sparse structural matrices.
//!
//! Supported: `%%MatrixMarket matrix coordinate {real|integer|double} {general|symmetric|skew-symmetric}`.
//! Symmetric and skew-symmetric files are expanded so that the returned matrix stores both
//! triangles (the engine's [`crate::model::Matrix::Sparse`] convention). Structural matrices must
//! be square. Indices in the file are 1-based (Matrix Market's convention); the returned matrix is
//! 0-based.
//!
//! Every error names the file, the line (1-based) and what was expected there. Rejected: `array`
//! (dense) files, `complex`, `pattern` and `hermitian` fields, non-square sizes, truncated or
//! overlong entry lists, indices out of range, non-numeric or non-finite (NaN, inf) values, a
//! repeated entry, and a symmetric file that gives the same off-diagonal pair in both triangles.
use faer::sparse::{SparseColMat, Triplet};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// What went wrong reading a Matrix Market file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct MtxError {
    /// The file as given by the caller.
    pub file: String,
    /// 1-based line number (0 when the file cannot be opened at all).
    pub line: usize,
    /// What was found and what was expected.
    pub message: String,
    pub kind: MtxErrorKind,
}

/// Machine-readable class of an [`MtxError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MtxErrorKind {
    /// The file cannot be opened or read.
    Io,
    /// Missing or malformed `%%MatrixMarket` banner.
    Banner,
    /// A valid Matrix Market variant this reader does not accept (array, complex, pattern, …).
    Unsupported,
    /// Malformed or non-square size line.
    Size,
    /// Fewer entries than the size line announces.
    Truncated,
    /// More entries than the size line announces.
    TooManyEntries,
    /// A malformed entry line (wrong number of fields, non-numeric).
    Entry,
    /// Row or column index outside 1..=n (or in the wrong triangle for skew-symmetric).
    OutOfRange,
    /// NaN or infinite value.
    NotFinite,
    /// The same entry given twice (or both (i, j) and (j, i) in a symmetric file).
    Duplicate,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Symmetry {
    General,
    Symmetric,
    Skew,
}

/// Largest order accepted. Why: the size line is untrusted and the sparse matrix allocates its
/// column pointers (8 bytes per column) before any entry is stored: a 3-line file announcing
/// 10⁹ rows would take 8 GB. 2²⁴ ≈ 16.8 million DOFs is far beyond what one LU per harmonic can
/// handle anyway (the fine blade preset has 30 000).
pub const MAX_ORDER: usize = 1 << 24;

/// Reads a square Matrix Market coordinate file into a sparse matrix holding both triangles.
pub fn read_matrix_market(path: &Path) -> Result<SparseColMat<usize, f64>, MtxError> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| MtxError {
        file: name.clone(),
        line: 0,
        message: format!("cannot open the file: {e}"),
        kind: MtxErrorKind::Io,
    })?;
    parse_matrix_market(BufReader::new(file), &name)
}

/// Parses Matrix Market text from any reader; `name` identifies the source in error messages.
pub fn parse_matrix_market<R: Read>(reader: R, name: &str) -> Result<SparseColMat<usize, f64>, MtxError> {
    let err = |line: usize, kind: MtxErrorKind, message: String| MtxError { file: name.to_string(), line, message, kind };
    let mut lines = BufReader::new(reader).lines();
    let mut lineno = 0usize;
    let mut next_line = |lineno: &mut usize| -> Result<Option<String>, MtxError> {
        match lines.next() {
            None => Ok(None),
            Some(Ok(s)) => {
                *lineno += 1;
                Ok(Some(s))
            }
            Some(Err(e)) => Err(MtxError { file: name.to_string(), line: *lineno + 1, message: format!("cannot read this line: {e}"), kind: MtxErrorKind::Io }),
        }
    };

    // Banner.
    let banner = next_line(&mut lineno)?
        .ok_or_else(|| err(1, MtxErrorKind::Banner, "empty file; expected the banner `%%MatrixMarket matrix coordinate real symmetric`".into()))?;
    let words: Vec<String> = banner.split_whitespace().map(|w| w.to_ascii_lowercase()).collect();
    if words.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(err(1, MtxErrorKind::Banner, format!("expected the banner `%%MatrixMarket matrix coordinate real symmetric`, found `{}`", banner.trim())));
    }
    if words.len() != 5 {
        return Err(err(
            1,
            MtxErrorKind::Banner,
            format!("the banner needs 5 words (`%%MatrixMarket matrix coordinate real symmetric`), found {}", words.len()),
        ));
    }
    if words[1] != "matrix" {
        return Err(err(1, MtxErrorKind::Unsupported, format!("object `{}` is not supported; expected `matrix`", words[1])));
    }
    match words[2].as_str() {
        "coordinate" => {}
        "array" => return Err(err(1, MtxErrorKind::Unsupported, "format `array` (dense) is not supported; expected `coordinate` (sparse)".into())),
        other => return Err(err(1, MtxErrorKind::Unsupported, format!("format `{other}` is not supported; expected `coordinate`"))),
    }
    match words[3].as_str() {
        "real" | "double" | "integer" => {}
        "complex" | "pattern" => {
            return Err(err(1, MtxErrorKind::Unsupported, format!("field `{}` is not supported; expected `real` (or `integer`)", words[3])));
        }
        other => return Err(err(1, MtxErrorKind::Unsupported, format!("field `{other}` is not supported; expected `real`"))),
    }
    let symmetry = match words[4].as_str() {
        "general" => Symmetry::General,
        "symmetric" => Symmetry::Symmetric,
        "skew-symmetric" => Symmetry::Skew,
        "hermitian" => return Err(err(1, MtxErrorKind::Unsupported, "symmetry `hermitian` is for complex matrices; expected `symmetric` or `general`".into())),
        other => {
            return Err(err(1, MtxErrorKind::Unsupported, format!("symmetry `{other}` is not supported; expected `symmetric`, `general` or `skew-symmetric`")));
        }
    };

    // Size line (after comments and blank lines).
    let (size_line, size_no) = loop {
        match next_line(&mut lineno)? {
            None => return Err(err(lineno + 1, MtxErrorKind::Truncated, "file ends before the size line `rows columns entries`".into())),
            Some(l) => {
                let t = l.trim();
                if t.is_empty() || t.starts_with('%') {
                    continue;
                }
                break (l, lineno);
            }
        }
    };
    let fields: Vec<&str> = size_line.split_whitespace().collect();
    if fields.len() != 3 {
        return Err(err(size_no, MtxErrorKind::Size, format!("expected the size line `rows columns entries` (3 integers), found `{}`", size_line.trim())));
    }
    let parse_count = |s: &str, what: &str| -> Result<usize, MtxError> {
        s.parse::<usize>().map_err(|_| err(size_no, MtxErrorKind::Size, format!("{what} `{s}` is not a non-negative integer")))
    };
    let nrows = parse_count(fields[0], "row count")?;
    let ncols = parse_count(fields[1], "column count")?;
    let nnz = parse_count(fields[2], "entry count")?;
    if nrows != ncols {
        return Err(err(size_no, MtxErrorKind::Size, format!("the matrix is {nrows}×{ncols}; a structural matrix must be square")));
    }
    let n = nrows;
    if n == 0 {
        return Err(err(size_no, MtxErrorKind::Size, "the matrix is 0×0; expected at least one row".into()));
    }
    if n > MAX_ORDER {
        return Err(err(size_no, MtxErrorKind::Size, format!("the matrix is {n}×{n}; at most {MAX_ORDER} rows are supported")));
    }
    let max_nnz = if symmetry == Symmetry::General { n.saturating_mul(n) } else { n.saturating_mul(n + 1) / 2 };
    if nnz > max_nnz {
        return Err(err(size_no, MtxErrorKind::Size, format!("{nnz} entries announced, more than a {n}×{n} {} matrix can hold ({max_nnz})", words[4])));
    }

    // Entries: (row, col, value, line).
    // No up-front reservation beyond what a line-sized file could hold: the size line is
    // untrusted (`100000 100000 10000000000` would ask for 320 GB and abort the process).
    let mut entries: Vec<(usize, usize, f64, usize)> = Vec::with_capacity(nnz.min(1 << 16));
    while entries.len() < nnz {
        let Some(l) = next_line(&mut lineno)? else {
            return Err(err(
                lineno + 1,
                MtxErrorKind::Truncated,
                format!("file ends after {} of the {nnz} entries announced on line {size_no}", entries.len()),
            ));
        };
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        if f.len() != 3 {
            return Err(err(lineno, MtxErrorKind::Entry, format!("expected an entry `row column value` (3 fields), found {} field(s): `{t}`", f.len())));
        }
        let index = |s: &str, what: &str| -> Result<usize, MtxError> {
            let v = s.parse::<i64>().map_err(|_| err(lineno, MtxErrorKind::Entry, format!("{what} index `{s}` is not an integer")))?;
            if v < 1 || v as u64 > n as u64 {
                return Err(err(lineno, MtxErrorKind::OutOfRange, format!("{what} index {v} is outside 1..={n}")));
            }
            Ok(v as usize - 1)
        };
        let i = index(f[0], "row")?;
        let j = index(f[1], "column")?;
        let v = f[2].parse::<f64>().map_err(|_| err(lineno, MtxErrorKind::Entry, format!("value `{}` is not a number", f[2])))?;
        if !v.is_finite() {
            return Err(err(lineno, MtxErrorKind::NotFinite, format!("value `{}` is not finite", f[2])));
        }
        if symmetry == Symmetry::Skew && i == j {
            return Err(err(lineno, MtxErrorKind::OutOfRange, format!("a skew-symmetric file has no diagonal entries, found ({}, {})", i + 1, j + 1)));
        }
        entries.push((i, j, v, lineno));
    }
    // Anything else must be blank or a comment.
    while let Some(l) = next_line(&mut lineno)? {
        let t = l.trim();
        if !(t.is_empty() || t.starts_with('%')) {
            return Err(err(lineno, MtxErrorKind::TooManyEntries, format!("unexpected data after the {nnz} entries announced on line {size_no}: `{t}`")));
        }
    }

    // Duplicates: in a symmetric file (i, j) and (j, i) are the same entry.
    let key = |e: &(usize, usize, f64, usize)| if symmetry == Symmetry::General { (e.1, e.0) } else { (e.0.min(e.1), e.0.max(e.1)) };
    let mut order: Vec<usize> = (0..entries.len()).collect();
    order.sort_unstable_by_key(|&k| (key(&entries[k]), entries[k].3));
    for w in order.windows(2) {
        let (a, b) = (&entries[w[0]], &entries[w[1]]);
        if key(a) == key(b) {
            let msg = if symmetry != Symmetry::General && (a.0 != b.0) {
                format!(
                    "entry ({}, {}) mirrors ({}, {}) given on line {}: a {} file stores one triangle only",
                    b.0 + 1,
                    b.1 + 1,
                    a.0 + 1,
                    a.1 + 1,
                    a.3,
                    words[4]
                )
            } else {
                format!("entry ({}, {}) was already given on line {}", b.0 + 1, b.1 + 1, a.3)
            };
            return Err(err(b.3, MtxErrorKind::Duplicate, msg));
        }
    }

    let mut triplets = Vec::with_capacity(if symmetry == Symmetry::General { nnz } else { 2 * nnz });
    for &(i, j, v, _) in &entries {
        triplets.push(Triplet::new(i, j, v));
        if i != j {
            match symmetry {
                Symmetry::General => {}
                Symmetry::Symmetric => triplets.push(Triplet::new(j, i, v)),
                Symmetry::Skew => triplets.push(Triplet::new(j, i, -v)),
            }
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(|e| err(size_no, MtxErrorKind::Size, format!("cannot build the sparse matrix: {e:?}")))
}

/// Writes `a` as Matrix Market coordinate real. With `symmetric`, only the lower triangle is
/// written (the caller asserts that `a` is symmetric; use [`is_symmetric`] to check).
/// Values are written in shortest round-trip form, so reading back gives the same bits.
pub fn write_matrix_market(path: &Path, a: &SparseColMat<usize, f64>, symmetric: bool) -> std::io::Result<()> {
    std::fs::write(path, matrix_market_string(a, symmetric))
}

/// The Matrix Market text of `a` (see [`write_matrix_market`]).
pub fn matrix_market_string(a: &SparseColMat<usize, f64>, symmetric: bool) -> String {
    let mut body = String::new();
    let mut count = 0usize;
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if symmetric && i < j {
                continue;
            }
            let _ = writeln!(body, "{} {} {:e}", i + 1, j + 1, v);
            count += 1;
        }
    }
    let kind = if symmetric { "symmetric" } else { "general" };
    format!("%%MatrixMarket matrix coordinate real {kind}\n% written by periodic-contact\n{} {} {count}\n{body}", a.nrows(), a.ncols())
}

/// True when `a` equals its transpose entry by entry, to a relative tolerance `rtol` of the
/// largest magnitude in `a`.
pub fn is_symmetric(a: &SparseColMat<usize, f64>, rtol: f64) -> bool {
    if a.nrows() != a.ncols() {
        return false;
    }
    let scale = a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let get = |i: usize, j: usize| -> f64 {
        let rows = a.row_idx_of_col_raw(j);
        rows.binary_search(&i).map_or(0.0, |p| a.val_of_col(j)[p])
    };
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if (v - get(j, i)).abs() > rtol * scale {
                return false;
            }
        }
    }
    true
}

impl From<MtxError> for crate::Error {
    fn from(e: MtxError) -> Self {
        if e.kind == MtxErrorKind::Io { crate::Error::io(e.to_string()) } else { crate::Error::input(e.to_string()) }
    }
}
