//! CalculiX's matrix output: `*FREQUENCY, SOLVER=MATRIXSTORAGE` writes, for job `jobname`,
//! `jobname.sti` (stiffness) and `jobname.mas` (mass) as lines `row column value` (1-based, one
//! triangle of the symmetric matrix: row ≤ column, verified with ccx 2.20), and `jobname.dof`, one
//! line `node.direction` per matrix row (`12.1` = node 12, x). DOFs fixed by `*BOUNDARY` are
//! already removed: the `.dof` map says which remain.
//!
//! Every error names the file, the line (1-based) and the remedy.
mod entry;

use super::nodes::NodeMap;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use std::path::{Path, PathBuf};

/// A CalculiX job's matrices and its node map, in the `.dof` order.
#[derive(Clone, Debug)]
pub struct CalculixModel {
    pub mass: SparseColMat<usize, f64>,
    pub stiffness: SparseColMat<usize, f64>,
    pub nodes: NodeMap,
}

/// What is wrong with one of a job's files.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct CalculixError {
    pub file: String,
    /// 1-based; 0 when the file cannot be read at all.
    pub line: usize,
    pub message: String,
}

/// The three files of job `stem` (`stem.sti`, `stem.mas`, `stem.dof`).
pub fn job_files(stem: &Path) -> [PathBuf; 3] {
    ["sti", "mas", "dof"].map(|ext| {
        let mut p = stem.as_os_str().to_owned();
        p.push(".");
        p.push(ext);
        PathBuf::from(p)
    })
}

const REGENERATE: &str = "regenerate it with `ccx JOBNAME` from a deck with *FREQUENCY, SOLVER=MATRIXSTORAGE";

/// Reads job `stem`: `stem.dof` first (it fixes the order n), then `stem.sti` and `stem.mas`, the
/// two matrices side by side (each is a third of a real blade's set-up). The mass matrix leaves out
/// its exact zeros: C3D8I's incompatible-mode DOFs carry none (66 % of a real blade's `.mas` lines),
/// and every product with M is the same without them.
pub fn read_calculix(stem: &Path) -> Result<CalculixModel, CalculixError> {
    let [sti, mas, dof] = job_files(stem);
    let nodes = parse_dof(&read(&dof)?, &dof.display().to_string())?;
    let n = count_dofs(&nodes);
    let dof_name = dof.display().to_string();
    let matrix = |path: &Path, zeros| {
        let cpu0 = super::profile_cpu();
        let text = read(path)?;
        let cpu1 = super::profile_cpu();
        let a = parse(&text, &path.display().to_string(), n, &dof_name, zeros);
        if let (Some(c0), Some(c1), Some(c2)) = (cpu0, cpu1, super::profile_cpu()) {
            eprintln!("set-up profile: {} thread CPU read {:.3} s, parse {:.3} s", path.display(), c1 - c0, c2 - c1);
        }
        a
    };
    let (stiffness, mass) = std::thread::scope(|s| {
        let mass = s.spawn(|| matrix(&mas, Zeros::Drop));
        let stiffness = matrix(&sti, Zeros::Keep);
        (stiffness, mass.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
    });
    // The stiffness's error first (the .sti is named before the .mas, as when read in turn).
    let stiffness = stiffness?;
    Ok(CalculixModel { mass: mass?, stiffness, nodes })
}

fn count_dofs(nodes: &NodeMap) -> usize {
    nodes.iter().map(|(_, d)| d.dofs.iter().flatten().count()).sum()
}

fn read(path: &Path) -> Result<String, CalculixError> {
    std::fs::read_to_string(path).map_err(|e| CalculixError {
        file: path.display().to_string(),
        line: 0,
        message: format!("cannot read the file: {e}; {REGENERATE}"),
    })
}

/// A `.dof` map: line i (1-based) is matrix row i, `node.direction` with direction 1, 2 or 3.
pub fn parse_dof(text: &str, file: &str) -> Result<NodeMap, CalculixError> {
    let name = Path::new(file).file_name().map_or(file.to_string(), |n| n.to_string_lossy().into_owned());
    let mut map = NodeMap::new(name, "it is fixed by *BOUNDARY or not in the mesh; choose a free node and direction of the deck");
    let mut row = 0;
    for (i, line) in text.lines().enumerate() {
        let err = |message: String| CalculixError { file: file.to_string(), line: i + 1, message };
        let s = line.trim();
        if s.is_empty() {
            continue;
        }
        let parsed = s.split_once('.').and_then(|(node, dir)| Some((node.parse::<u64>().ok()?, dir.parse::<usize>().ok()?)));
        let Some((node, dir)) = parsed else {
            return Err(err(format!("\"{s}\" is not node.direction (e.g. 12.1 = node 12, x); {REGENERATE}")));
        };
        if !(1..=3).contains(&dir) {
            return Err(err(format!("\"{s}\": direction {dir}, expected 1, 2 or 3 (x, y, z); only displacement DOFs of solid elements are supported")));
        }
        if map.insert(node, dir - 1, row).is_some() {
            return Err(err(format!("\"{s}\": node {node} direction {dir} is listed twice; {REGENERATE}")));
        }
        row += 1;
    }
    if row == 0 {
        return Err(CalculixError { file: file.to_string(), line: 0, message: format!("lists no DOF; {REGENERATE}") });
    }
    Ok(map)
}

/// Whether a matrix keeps the entries written as exactly 0.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Zeros {
    Keep,
    Drop,
}

/// A `.sti` or `.mas` file of order `n` (the `.dof` map's count, from `dof_file`): both triangles
/// are returned; each pair may be given once, in either triangle. One pass over the lines without
/// allocating per line; the repeated-pair check sorts only when the pairs are not in ccx's order.
pub fn parse_matrix(text: &str, file: &str, n: usize, dof_file: &str) -> Result<SparseColMat<usize, f64>, CalculixError> {
    parse(text, file, n, dof_file, Zeros::Keep)
}

fn parse(text: &str, file: &str, n: usize, dof_file: &str, zeros: Zeros) -> Result<SparseColMat<usize, f64>, CalculixError> {
    // (row, column, value), 1-based, in file order.
    let mut entries: Vec<(u32, u32, f64)> = Vec::with_capacity(text.len() / 30);
    let mut max_index = 0;
    let key = |r: usize, c: usize| r.max(c) as u64 * (n as u64 + 1) + r.min(c) as u64;
    let (mut last_key, mut in_order) = (0, true);
    for (i, line) in text.lines().enumerate() {
        let err = |message: String| CalculixError { file: file.to_string(), line: i + 1, message };
        // ccx's lines take the byte reader; the general one for the rest (blank lines too).
        let fast = entry::fast_entry(line.as_bytes());
        if fast.is_none() && line.trim_ascii().is_empty() {
            continue;
        }
        let Some(((r, c), v)) = fast.or_else(|| matrix_entry(line)) else {
            return Err(err(format!("\"{}\" is not `row column value` (1-based indices, a number); {REGENERATE}", line.trim())));
        };
        if r == 0 || c == 0 || r > n || c > n || n > u32::MAX as usize {
            return Err(err(format!("entry ({r}, {c}) is outside 1..{n}, the DOFs listed in {dof_file}: the files come from different runs; {REGENERATE}")));
        }
        if !v.is_finite() {
            return Err(err(format!("value {v} is not finite; {REGENERATE}")));
        }
        max_index = max_index.max(r.max(c));
        // ccx writes column by column, row ≤ column: keys strictly increasing, no pair twice.
        in_order &= key(r, c) > last_key;
        last_key = key(r, c);
        entries.push((r as u32, c as u32, v));
    }
    if !in_order {
        // (key, line) of every entry: the first repeat in file order is reported.
        let mut keys: Vec<(u64, usize)> = text.lines().enumerate().filter_map(|(i, l)| matrix_entry(l).map(|((r, c), _)| (key(r, c), i))).collect();
        keys.sort_unstable();
        if let Some(line) = keys.windows(2).filter(|w| w[0].0 == w[1].0).map(|w| w[1].1).min() {
            let (r, c) = text.lines().nth(line).and_then(matrix_entry).map_or((0, 0), |e| e.0);
            return Err(CalculixError {
                file: file.to_string(),
                line: line + 1,
                message: format!("entry ({r}, {c}) is given twice (a symmetric matrix stores one triangle); {REGENERATE}"),
            });
        }
    }
    if max_index < n {
        return Err(CalculixError {
            file: file.to_string(),
            line: 0,
            message: format!("has rows up to {max_index} but {dof_file} lists {n} DOFs: the files come from different runs; {REGENERATE}"),
        });
    }
    if zeros == Zeros::Drop {
        entries.retain(|e| e.2 != 0.0);
    }
    if in_order {
        return Ok(symmetric_from_ordered(n, &entries));
    }
    let mut triplets = Vec::with_capacity(2 * entries.len());
    for &(r, c, v) in &entries {
        let (r, c) = (r as usize, c as usize);
        triplets.push(Triplet::new(r - 1, c - 1, v));
        if r != c {
            triplets.push(Triplet::new(c - 1, r - 1, v));
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(|e| CalculixError {
        file: file.to_string(),
        line: 0,
        message: format!("cannot build the sparse matrix: {e:?}"),
    })
}

/// Both triangles from one triangle's entries (1-based) in ccx's order (by column, then row; no
/// pair twice), straight into compressed columns: column j receives first its own file column's
/// rows ≤ j, then the mirrored rows > j of the later file columns, each ascending, so no sort.
fn symmetric_from_ordered(n: usize, entries: &[(u32, u32, f64)]) -> SparseColMat<usize, f64> {
    let lo_hi = |r: u32, c: u32| (r.min(c) as usize - 1, r.max(c) as usize - 1);
    // col_ptr[j + 1] counts column j first, then becomes its end by the running sum.
    let mut col_ptr = vec![0usize; n + 1];
    for &(r, c, _) in entries {
        let (lo, hi) = lo_hi(r, c);
        col_ptr[hi + 1] += 1;
        if lo != hi {
            col_ptr[lo + 1] += 1;
        }
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut next = col_ptr[..n].to_vec();
    let (mut row_idx, mut val) = (vec![0usize; col_ptr[n]], vec![0.0; col_ptr[n]]);
    let mut put = |col: usize, row: usize, v: f64| {
        row_idx[next[col]] = row;
        val[next[col]] = v;
        next[col] += 1;
    };
    for &(r, c, v) in entries {
        let (lo, hi) = lo_hi(r, c);
        put(hi, lo, v);
        if lo != hi {
            put(lo, hi, v);
        }
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), val)
}

/// `row column value` of one line without allocating; `None` for anything else (a blank line too).
fn matrix_entry(line: &str) -> Option<((usize, usize), f64)> {
    let mut words = line.split_ascii_whitespace();
    match (words.next(), words.next(), words.next(), words.next()) {
        (Some(r), Some(c), Some(v), None) => r.parse::<usize>().ok().zip(c.parse::<usize>().ok()).zip(v.parse::<f64>().ok()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_job_is_read_with_both_triangles_and_its_node_map() {
        let nodes = parse_dof("5.1\n5.2\n7.3\n", "j.dof").unwrap();
        assert_eq!((nodes.dof(5, 1).unwrap(), nodes.dof(7, 2).unwrap()), (1, 2));
        let e = nodes.dof(7, 0).unwrap_err().to_string();
        assert_eq!(e, "node 7 direction x is not in j.dof: it is fixed by *BOUNDARY or not in the mesh; choose a free node and direction of the deck");
        let k = parse_matrix("1 1 2.0\n1 2 -1.0\n2 2 2.0\n2 3 -0.5\n3 3 1.0\n", "j.sti", 3, "j.dof").unwrap();
        let dense = k.to_dense();
        assert_eq!((dense[(1, 0)], dense[(0, 1)], dense[(2, 1)], dense[(2, 2)]), (-1.0, -1.0, -0.5, 1.0));
        // Any order, either triangle, blank lines: the same matrix.
        let shuffled = parse_matrix("3 2 -0.5\n\n2 2 2.0\n1 1 2.0\n3 3 1.0\n2 1 -1.0\n", "j.sti", 3, "j.dof").unwrap();
        assert_eq!(shuffled.to_dense(), dense);
    }

    #[test]
    fn bad_lines_are_refused_with_file_and_line() {
        let e = parse_dof("5.1\nfive.2\n", "j.dof").unwrap_err();
        assert_eq!((e.line, e.file.as_str()), (2, "j.dof"));
        assert!(parse_dof("5.1\n5.4\n", "j.dof").unwrap_err().message.contains("direction 4"));
        assert!(parse_dof("5.1\n5.1\n", "j.dof").unwrap_err().message.contains("twice"));
        let e = parse_matrix("1 1 2.0\n1 x 1\n", "j.sti", 2, "j.dof").unwrap_err();
        assert_eq!(e.line, 2);
        let e = parse_matrix("1 1 2.0\n1 3 1.0\n", "j.sti", 2, "j.dof").unwrap_err();
        assert!(e.message.contains("outside 1..2"), "{e}");
        let e = parse_matrix("1 1 2.0\n", "j.sti", 2, "j.dof").unwrap_err();
        assert!(e.message.contains("lists 2 DOFs"), "{e}");
        let e = parse_matrix("1 1 2.0\n2 1 1\n1 2 1\n2 2 1\n", "j.sti", 2, "j.dof").unwrap_err();
        assert!(e.message.contains("entry (1, 2) is given twice") && e.line == 3, "{e}");
        // Out of ccx's order, the first repeat in file order is the one named.
        let e = parse_matrix("2 2 1\n1 1 2.0\n\n2 2 3\n1 1 1\n", "j.sti", 2, "j.dof").unwrap_err();
        assert!(e.message.contains("entry (2, 2) is given twice") && e.line == 4, "{e}");
        let e = parse_matrix("1 1 2.0\n0 1 1\n", "j.sti", 2, "j.dof").unwrap_err();
        assert!(e.message.contains("outside 1..2") && e.line == 2, "{e}");
    }
}
