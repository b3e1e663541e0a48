//! Siconos' dense `.dat` LCP format: reader and writer.
//!
//! Layout, as Siconos writes it (`numerics/src/LCP/test/data/`):
//! ```text
//! n                 size of the LCP
//! 0                 storage type of M (0 = dense; nothing else is supported here)
//! n                 rows of M
//! n                 columns of M
//! n<TAB>n           the dimensions again (any whitespace accepted)
//! m11 m21 … mn1     n lines: the COLUMNS of M, one per line (see below)
//! …
//! q1 q2 … qn        one line
//! anything else     a free comment
//! ```
//! **Column-major.** Siconos keeps a dense matrix column-major (`matrix0[i + j·size0]`) and its
//! `NM_write_in_file` / `NM_new_from_file` write and read `matrix0` sequentially (a newline every
//! n values), so the k-th line of the matrix block is column k of M, not row k. The data confirm
//! it: `lcp_Pang_isolated_sol` has its isolated solution z = (1, 0, 0) only when read this way,
//! and Murty's `lcp_exp_murty2` (M upper triangular, Murty 1988 ch. 6) takes Lemke's method
//! exactly 2⁶ pivots only this way. For symmetric M the two readings agree.
//!
//! Blank lines between items are skipped. Every value must be a finite number. The reader never
//! panics: every malformed input gives a [`DatError`] naming the file, the line, what was expected
//! and what was found.
use std::fmt::Write as _;
use std::io;
use std::path::Path;

use crate::lcp::{DenseMatrix, LcpMatrix};

/// A `.dat` file that cannot be read or parsed.
#[derive(Debug, thiserror::Error)]
pub enum DatError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: io::Error,
    },
    /// `line` is 1-based; for a truncated file it is the line after the last one.
    #[error("{file} line {line}: expected {expected}, found {found}")]
    Syntax { file: String, line: usize, expected: String, found: String },
    #[error("{file} line {line}: storage type {found}: only dense storage (0) is supported")]
    UnsupportedStorage { file: String, line: usize, found: String },
}

/// Reads a dense Siconos `.dat` LCP: (M, q).
pub fn read_dat(path: &Path) -> Result<(DenseMatrix, Vec<f64>), DatError> {
    let name = path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string());
    let bytes = std::fs::read(path).map_err(|source| DatError::Io { file: name.clone(), source })?;
    // Invalid UTF-8 (e.g. in a comment) is replaced, not rejected; numbers are ASCII anyway.
    let text = String::from_utf8_lossy(&bytes);
    parse_dat(&text, &name)
}

/// Parses the text of a dense Siconos `.dat` LCP; `source` names it in errors.
pub fn parse_dat(text: &str, source: &str) -> Result<(DenseMatrix, Vec<f64>), DatError> {
    let mut p = Parser { lines: text.lines().enumerate(), source, last_line: 0 };

    let (line, tok) = p.single("the size n (a positive integer)")?;
    let n = match tok.parse::<usize>() {
        Ok(n) if n > 0 => n,
        _ => return Err(p.err(line, "the size n (a positive integer)", quote(tok))),
    };
    let nn = match n.checked_mul(n) {
        Some(nn) if nn < usize::MAX / 16 => nn,
        _ => return Err(p.err(line, "a size n whose n×n matrix fits in memory", quote(tok))),
    };

    let (line, tok) = p.single("the storage type (0 = dense)")?;
    match tok.parse::<i64>() {
        Ok(0) => {}
        Ok(_) => return Err(DatError::UnsupportedStorage { file: source.to_string(), line, found: tok.to_string() }),
        Err(_) => return Err(p.err(line, "the storage type (0 = dense)", quote(tok))),
    }
    for what in ["the number of rows of M", "the number of columns of M"] {
        let expected = format!("{what} ({n})");
        let (line, tok) = p.single(&expected)?;
        if tok.parse::<usize>() != Ok(n) {
            return Err(p.err(line, &expected, quote(tok)));
        }
    }
    let expected = format!("the dimensions of M (\"{n} {n}\")");
    let (line, toks) = p.next_line(&expected)?;
    if toks.len() != 2 || toks.iter().any(|t| t.parse::<usize>() != Ok(n)) {
        return Err(p.err(line, &expected, quote(&toks.join(" "))));
    }

    // No up-front reservation of n² values: memory grows only with what the text really holds.
    let mut data = Vec::with_capacity(nn.min(text.len() / 2 + 1));
    for col in 0..n {
        let what = format!("column {} of M", col + 1);
        p.values(n, &what, &mut data)?;
    }
    let mut q = Vec::with_capacity(n);
    p.values(n, "q", &mut q)?;
    // The rest of the text is a comment. `data` is column-major: entry (i, j) is data[j·n + i].
    Ok((DenseMatrix::from_fn(n, |i, j| data[j * n + i]), q))
}

/// Writes (M, q) as a dense Siconos `.dat` file (one column of M per line, as Siconos does).
/// Values are written in Rust's shortest round-trip form, so reading the file back gives the
/// same numbers bit for bit.
/// Non-finite values or a size mismatch give an `InvalidInput` error.
pub fn write_dat(path: &Path, a: &dyn LcpMatrix, q: &[f64]) -> io::Result<()> {
    let n = a.dim();
    if q.len() != n {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("q has {} entries for a {n}×{n} matrix", q.len())));
    }
    if !a.max_abs().1 || !q.iter().all(|v| v.is_finite()) {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, "non-finite value in M or q"));
    }
    let mut s = String::new();
    let _ = write!(s, "{n}\n0\n{n}\n{n}\n{n}\t{n}\n");
    let mut col = vec![0.0; n];
    for j in 0..n {
        a.column_into(j, &mut col);
        push_values(&mut s, &col);
    }
    push_values(&mut s, q);
    std::fs::write(path, s)
}

fn push_values(s: &mut String, values: &[f64]) {
    for (k, v) in values.iter().enumerate() {
        if k > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{v:e}");
    }
    s.push('\n');
}

fn quote(s: &str) -> String {
    const MAX: usize = 60;
    if s.chars().count() > MAX {
        let head: String = s.chars().take(MAX).collect();
        format!("\"{head}…\"")
    } else {
        format!("\"{s}\"")
    }
}

struct Parser<'t> {
    lines: std::iter::Enumerate<std::str::Lines<'t>>,
    source: &'t str,
    last_line: usize,
}

impl<'t> Parser<'t> {
    fn err(&self, line: usize, expected: &str, found: String) -> DatError {
        DatError::Syntax { file: self.source.to_string(), line, expected: expected.to_string(), found }
    }

    /// The next non-blank line (1-based number, tokens), or a "found end of file" error.
    fn next_line(&mut self, expected: &str) -> Result<(usize, Vec<&'t str>), DatError> {
        for (k, l) in self.lines.by_ref() {
            self.last_line = k + 1;
            let toks: Vec<&str> = l.split_whitespace().collect();
            if !toks.is_empty() {
                return Ok((k + 1, toks));
            }
        }
        Err(self.err(self.last_line + 1, expected, "end of file (truncated)".to_string()))
    }

    /// A line holding exactly one token.
    fn single(&mut self, expected: &str) -> Result<(usize, &'t str), DatError> {
        let (line, toks) = self.next_line(expected)?;
        if toks.len() != 1 {
            return Err(self.err(line, expected, quote(&toks.join(" "))));
        }
        Ok((line, toks[0]))
    }

    /// A line of exactly `n` finite numbers, appended to `out`.
    fn values(&mut self, n: usize, what: &str, out: &mut Vec<f64>) -> Result<(), DatError> {
        let expected = format!("{n} values of {what}");
        let (line, toks) = self.next_line(&expected)?;
        if toks.len() != n {
            return Err(self.err(line, &expected, toks.len().to_string()));
        }
        for (k, t) in toks.iter().enumerate() {
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => out.push(v),
                Ok(_) => {
                    return Err(self.err(line, &format!("a finite number (value {} of {what})", k + 1), quote(t)));
                }
                Err(_) => return Err(self.err(line, &format!("a number (value {} of {what})", k + 1), quote(t))),
            }
        }
        Ok(())
    }
}

impl From<DatError> for crate::Error {
    fn from(e: DatError) -> Self {
        match e {
            DatError::Io { .. } => crate::Error::io(e.to_string()),
            _ => crate::Error::input(e.to_string()),
        }
    }
}
