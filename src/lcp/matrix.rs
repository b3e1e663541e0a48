//! Matrix access for LCP solvers: dense, or block-circulant without forming it.

/// What an LCP solver needs of A.
pub trait LcpMatrix: Sync {
    fn dim(&self) -> usize;
    fn entry(&self, i: usize, j: usize) -> f64;
    /// Column j of A into `out` (length dim).
    fn column_into(&self, j: usize, out: &mut [f64]);
    /// out = A z.
    fn mul_into(&self, z: &[f64], out: &mut [f64]);
    /// max |a_ij|, and whether every entry is finite.
    fn max_abs(&self) -> (f64, bool);
    /// w_i += (A z)_i for the rows i with `rows[i]`, summed directly over the non-zero z_j (no
    /// FFT): the certification's exact recheck, whose round-off is that of a plain sum. Column by
    /// column unless a structure does better.
    fn direct_mul_add(&self, z: &[f64], rows: &[bool], w: &mut [f64]) {
        let mut col = vec![0.0; self.dim()];
        for (j, &zj) in z.iter().enumerate() {
            if zj != 0.0 {
                self.column_into(j, &mut col);
                w.iter_mut().zip(&col).zip(rows).filter(|(_, r)| **r).for_each(|((wi, c), _)| *wi += c * zj);
            }
        }
    }
}

/// A dense n×n matrix stored row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseMatrix {
    n: usize,
    data: Vec<f64>,
}

impl DenseMatrix {
    /// `data` holds n·n values, row after row. Panics on a length mismatch (a programming error).
    pub fn from_row_major(n: usize, data: Vec<f64>) -> Self {
        assert_eq!(data.len(), n * n, "DenseMatrix: {} values for {n}×{n}", data.len());
        DenseMatrix { n, data }
    }
    pub fn from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                data.push(f(i, j));
            }
        }
        DenseMatrix { n, data }
    }
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.n..(i + 1) * self.n]
    }
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }
    /// A dense copy of any LCP matrix.
    pub fn from_matrix(a: &dyn LcpMatrix) -> Self {
        let n = a.dim();
        let mut data = vec![0.0; n * n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            a.column_into(j, &mut col);
            for i in 0..n {
                data[i * n + j] = col[i];
            }
        }
        DenseMatrix { n, data }
    }
}

impl LcpMatrix for DenseMatrix {
    fn dim(&self) -> usize {
        self.n
    }
    fn entry(&self, i: usize, j: usize) -> f64 {
        self.data[i * self.n + j]
    }
    fn column_into(&self, j: usize, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.data[i * self.n + j];
        }
    }
    fn mul_into(&self, z: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.row(i).iter().zip(z).map(|(a, b)| a * b).sum();
        }
    }
    fn max_abs(&self) -> (f64, bool) {
        let finite = self.data.iter().all(|v| v.is_finite());
        (self.data.iter().fold(0.0f64, |m, v| m.max(v.abs())), finite)
    }
}

/// A block-circulant matrix of k×k blocks of size m×m, indexed time-major: row (j, a) is j·m + a.
/// Entry ((j, a), (l, b)) = blocks[d][a][b] with d = (j − l) mod k: k·m² numbers in all.
#[derive(Clone, Debug)]
pub struct BlockCirculant {
    k: usize,
    m: usize,
    /// blocks[(d·m + a)·m + b]; formed from `spectrum` on first use when the matrix was made from
    /// its spectrum ([`BlockCirculant::from_spectrum`]).
    blocks: std::sync::OnceLock<Vec<f64>>,
    /// The blocks' DFT when the caller had it (Ĝ_p row-major m×m, p = 0..=k/2): the FFT
    /// products then skip the m² transforms of [`super::CirculantOperator`].
    /// Shared: it is often the frequency-domain assembly's own (`PeriodicProblem::lcp`).
    spectrum: Option<std::sync::Arc<Vec<num_complex::Complex64>>>,
    /// The DC and Nyquist bins' imaginary parts of `spectrum` are read as 0 (a real block's
    /// transform has none; an assembly's are round-off it keeps), [`Self::with_real_ends`].
    real_ends: bool,
    /// [`Self::max_abs_bound`] from the spectrum, once: a solve asks for it two or three times
    /// (the finiteness check, the certification's round-off bound), each a pass over k/2·m².
    bound: std::sync::OnceLock<(f64, bool)>,
}

/// Equal blocks are equal matrices, whether a spectrum came with them or not.
impl PartialEq for BlockCirculant {
    fn eq(&self, other: &Self) -> bool {
        (self.k, self.m) == (other.k, other.m) && self.blocks() == other.blocks()
    }
}

impl BlockCirculant {
    pub fn new(k: usize, m: usize, blocks: Vec<f64>) -> Self {
        assert_eq!(blocks.len(), k * m * m, "BlockCirculant: {} values for k={k}, m={m}", blocks.len());
        BlockCirculant { k, m, blocks: blocks.into(), spectrum: None, real_ends: false, bound: std::sync::OnceLock::new() }
    }
    /// The matrix of block spectrum Ĝ_p (as [`Self::with_spectrum`]), its blocks formed by inverse
    /// FFT only when something asks for them ([`Self::blocks`]). Why: a shooting solve needs
    /// only the spectrum (the FFT products) and a bound of max|A|; forming the k·m² blocks was
    /// a tenth of the real blade's 200-point sweep (issue 23).
    pub fn from_spectrum(k: usize, m: usize, spectrum: impl Into<std::sync::Arc<Vec<num_complex::Complex64>>>) -> Self {
        BlockCirculant { k, m, blocks: std::sync::OnceLock::new(), spectrum: None, real_ends: false, bound: std::sync::OnceLock::new() }.with_spectrum(spectrum)
    }
    /// The same matrix with its block spectrum Ĝ_p = Σ_d blocks[d] e^(−2πi pd/k) (row-major m×m,
    /// p = 0..=k/2), e.g. from the frequency-domain assembly it was transformed from.
    pub fn with_spectrum(mut self, spectrum: impl Into<std::sync::Arc<Vec<num_complex::Complex64>>>) -> Self {
        let spectrum = spectrum.into();
        assert_eq!(spectrum.len(), (self.k / 2 + 1) * self.m * self.m, "BlockCirculant: spectrum of {} values for k={}, m={}", spectrum.len(), self.k, self.m);
        self.spectrum = Some(spectrum);
        self.bound = std::sync::OnceLock::new();
        self
    }
    /// The same matrix with the imaginary parts of its spectrum's DC and Nyquist bins read as 0:
    /// a spectrum shared with an assembly that keeps their round-off, instead of a copy with them
    /// zeroed (4.7 MB per solve on the real blade at k = 2048, issue 23).
    pub fn with_real_ends(mut self) -> Self {
        self.real_ends = true;
        self.bound = std::sync::OnceLock::new();
        self
    }
    /// The block spectrum, when it came with the matrix; where [`Self::real_ends`], the DC and
    /// Nyquist bins' imaginary parts in it are to be read as 0.
    pub fn spectrum(&self) -> Option<&[num_complex::Complex64]> {
        self.spectrum.as_deref().map(Vec::as_slice)
    }
    /// Whether the DC and Nyquist bins' imaginary parts of [`Self::spectrum`] are read as 0.
    pub fn real_ends(&self) -> bool {
        self.real_ends
    }
    pub fn k(&self) -> usize {
        self.k
    }
    pub fn m(&self) -> usize {
        self.m
    }
    /// The first block column: block d is blocks()[d·m²..(d+1)·m²], row-major.
    pub fn blocks(&self) -> &[f64] {
        self.blocks.get_or_init(|| self.blocks_from_spectrum())
    }
    /// The blocks by inverse FFT of the spectrum, entry by entry (a, b).
    fn blocks_from_spectrum(&self) -> Vec<f64> {
        let (k, m) = (self.k, self.m);
        let spectrum = self.spectrum().expect("a BlockCirculant without blocks has its spectrum");
        let fft = crate::linalg::fft::PeriodFft::new(k);
        let mut blocks = vec![0.0; k * m * m];
        let mut column = vec![num_complex::Complex64::ZERO; k / 2 + 1];
        for e in 0..m * m {
            column.iter_mut().enumerate().for_each(|(p, v)| *v = spectrum[p * m * m + e]);
            for (d, v) in fft.inverse(&column).into_iter().enumerate() {
                blocks[d * m * m + e] = v;
            }
        }
        blocks
    }
    /// An upper bound of max |a_ij| and whether every entry is finite, without forming the blocks
    /// when they are not formed: |a_d| ≤ (1/k)·Σ_p |Ĝ_p| over the full (Hermitian) spectrum.
    /// Exact once the blocks are formed; the blocks are formed where the bound overflows.
    pub fn max_abs_bound(&self) -> (f64, bool) {
        let (Some(spectrum), None) = (self.spectrum(), self.blocks.get()) else { return self.max_abs() };
        *self.bound.get_or_init(|| self.bound_from_spectrum(spectrum))
    }
    /// [`Self::max_abs_bound`]'s pass over the spectrum.
    fn bound_from_spectrum(&self, spectrum: &[num_complex::Complex64]) -> (f64, bool) {
        let (k, mm) = (self.k, self.m * self.m);
        if mm == 0 {
            return (0.0, true);
        }
        let mut sums = vec![0.0f64; mm];
        for (p, block) in spectrum.chunks_exact(mm).enumerate() {
            // The bins 1..k/2 (but Nyquist) stand for their conjugates too.
            let end = p == 0 || 2 * p == k;
            let weight = if end { 1.0 } else { 2.0 };
            // |re| + |im| ≥ |g|: a bound still, without hypot's cost.
            let real = end && self.real_ends;
            sums.iter_mut().zip(block).for_each(|(s, g)| *s += weight * (g.re.abs() + if real { 0.0 } else { g.im.abs() }));
        }
        let sum = sums.iter().fold(0.0f64, |a, s| a.max(*s));
        // Near overflow the inverse FFT's own sums may not be finite: the blocks decide.
        if !sum.is_finite() {
            return self.max_abs();
        }
        (sum / k as f64, true)
    }
    /// Adds diag(values) (length m) to every diagonal block: A + I_k ⊗ diag(values).
    pub fn add_block_diagonal(&mut self, values: &[f64]) {
        let m = self.m;
        self.bound = std::sync::OnceLock::new();
        for (a, v) in values.iter().enumerate() {
            if let Some(blocks) = self.blocks.get_mut() {
                blocks[a * m + a] += v;
            }
            // Block 0 alone changes: every harmonic's diagonal by the same value.
            if let Some(s) = self.spectrum.as_mut().map(std::sync::Arc::make_mut) {
                s.chunks_exact_mut(m * m).for_each(|block| block[a * m + a] += v);
            }
        }
    }
    #[inline]
    fn block_entry(&self, d: usize, a: usize, b: usize) -> f64 {
        self.blocks()[(d * self.m + a) * self.m + b]
    }
}

impl BlockCirculant {
    /// Recognises a dense matrix that is exactly block-circulant (tolerance 0: every entry equals
    /// the one of the first block column it should repeat), trying block sizes m = 1..=max_m that
    /// divide n with at least two blocks (k ≥ 2), smallest first. O(n²) per m tried, with an
    /// early exit at the first mismatch.
    pub fn detect(a: &DenseMatrix, max_m: usize) -> Option<BlockCirculant> {
        let n = a.dim();
        for m in 1..=max_m.min(n / 2) {
            if !n.is_multiple_of(m) {
                continue;
            }
            let k = n / m;
            let first = |r: usize, b: usize| a.data[r * n + b];
            let mut ok = true;
            'rows: for i in 0..n {
                let (ji, ai) = (i / m, i % m);
                let row = a.row(i);
                for (j, &v) in row.iter().enumerate() {
                    let (l, b) = (j / m, j % m);
                    let d = (ji + k - l) % k;
                    if v != first(d * m + ai, b) {
                        ok = false;
                        break 'rows;
                    }
                }
            }
            if ok {
                let mut blocks = vec![0.0; k * m * m];
                for d in 0..k {
                    for ai in 0..m {
                        for b in 0..m {
                            blocks[(d * m + ai) * m + b] = first(d * m + ai, b);
                        }
                    }
                }
                return Some(BlockCirculant::new(k, m, blocks));
            }
        }
        None
    }
}

impl LcpMatrix for BlockCirculant {
    fn dim(&self) -> usize {
        self.k * self.m
    }
    fn entry(&self, i: usize, j: usize) -> f64 {
        let (ji, a) = (i / self.m, i % self.m);
        let (l, b) = (j / self.m, j % self.m);
        self.block_entry((ji + self.k - l) % self.k, a, b)
    }
    fn column_into(&self, j: usize, out: &mut [f64]) {
        let (l, b) = (j / self.m, j % self.m);
        for ji in 0..self.k {
            let d = (ji + self.k - l) % self.k;
            for a in 0..self.m {
                out[ji * self.m + a] = self.block_entry(d, a, b);
            }
        }
    }
    /// Direct O(k²m²) product; FFT-based products belong to the solvers that need them.
    fn mul_into(&self, z: &[f64], out: &mut [f64]) {
        let (k, m) = (self.k, self.m);
        out.iter_mut().for_each(|v| *v = 0.0);
        for ji in 0..k {
            for l in 0..k {
                let d = (ji + k - l) % k;
                for a in 0..m {
                    let mut s = 0.0;
                    for b in 0..m {
                        s += self.block_entry(d, a, b) * z[l * m + b];
                    }
                    out[ji * m + a] += s;
                }
            }
        }
    }
    fn max_abs(&self) -> (f64, bool) {
        let blocks = self.blocks();
        let finite = blocks.iter().all(|v| v.is_finite());
        (blocks.iter().fold(0.0f64, |m, v| m.max(v.abs())), finite)
    }
    /// Lag by lag: block d (in cache, and transposed once) meets every non-zero z_(l, b), an
    /// axpy of length m into step l + d, or the selected rows of that step alone. The same
    /// k·m·nnz(z) multiply-adds at most as column by column, but contiguous (column by column
    /// read every block with stride m: 70 % of a k = 2048 solve).
    fn direct_mul_add(&self, z: &[f64], rows: &[bool], w: &mut [f64]) {
        let (k, m) = (self.k, self.m);
        let nonzero: Vec<(usize, usize, f64)> = z.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(j, &v)| (j / m, j % m, v)).collect();
        // The selected rows of each step (`None`: all of them).
        let selected: Vec<Option<Vec<usize>>> = (0..k)
            .map(|j| {
                let sel: Vec<usize> = (0..m).filter(|&a| rows[j * m + a]).collect();
                (sel.len() < m).then_some(sel)
            })
            .collect();
        let mut transposed = vec![0.0; m * m];
        for lag in 0..k {
            let block = &self.blocks()[lag * m * m..(lag + 1) * m * m];
            if block.iter().all(|&v| v == 0.0) {
                continue;
            }
            for a in 0..m {
                for b in 0..m {
                    transposed[b * m + a] = block[a * m + b];
                }
            }
            for &(l, b, v) in &nonzero {
                let row = (l + lag) % k;
                let out = &mut w[row * m..(row + 1) * m];
                match &selected[row] {
                    None => out.iter_mut().zip(&transposed[b * m..(b + 1) * m]).for_each(|(o, c)| *o += c * v),
                    Some(sel) => sel.iter().for_each(|&a| out[a] += transposed[b * m + a] * v),
                }
            }
        }
    }
}
