//! A primal–dual interior-point method for the linear programs of the jerk-limited SCP
//! ([`super::jerk`]), whose rows each touch a few neighbouring columns (issue 11).
//!
//! Every row of a jerk subproblem involves the b and ü of one station or of the two ends of
//! one interval, so the Newton system of an interior-point iteration is banded: with the
//! columns in station order and each equality's multiplier placed right after its last column,
//! the regularised KKT matrix
//!
//! ```text
//! K = [ Gᵀ W G + ρ I   Eᵀ  ]      W = Λ S⁻¹ (inequality duals over slacks)
//!     [ E             −δ I ]
//! ```
//!
//! has a half-bandwidth of three to five, and its LDLᵀ factorisation (quasi-definite, so no
//! pivoting is needed) costs O(N·bw²). Clarabel treats the same matrix as a general sparse one
//! (ordering, symbolic analysis, its cone machinery). The factorisation is not where most of an
//! iteration goes, though: the products with the constraint matrix (a few per iteration, O(nnz)
//! each) cost about as much in either solver. Measured on the 20 COPP paths with jerk limits
//! (one thread, CPU time of the whole jerk-limited solve, the same minutes): 9.4 s with
//! Clarabel for every subproblem, 6.5 s with this solver; the LinuxCNC impeller with jerk =
//! 10 × acceleration (`benches/realworld.sh`, 2026-11-26 14:15 and 19:44): 27.9 → 16.3 s of
//! CPU, 14.3 → 8.4 s on two cores.
//!
//! The method is Mehrotra's predictor–corrector (Nocedal & Wright, *Numerical Optimization*,
//! 2nd ed., §14.2, also for the starting point's shift; the least-squares start is CVXOPT's,
//! Vandenberghe 2010) on
//!
//! ```text
//! minimise qᵀz   subject to   E z = f,   G z + s = h,   s ≥ 0,
//! ```
//!
//! after Ruiz equilibration of rows and columns (as Clarabel's), with the KKT matrix scaled to
//! unit pivots, one step of iterative refinement of the corrector's KKT solve against the unregularised
//! matrix, and Clarabel's stopping rule (primal and dual residuals below `tol_feas`, the
//! duality gap below `tol_gap`, absolute or relative) plus every row holding to `tol_feas` in
//! its own units ([`Lp::rows_hold`]). It does not detect infeasibility: a problem it does not
//! solve within its iteration cap (or one that is not banded) is an [`Err`], and the caller
//! hands it to Clarabel, which does.
//!
//! **Warm starts** ([`WarmStart`]). The SCP solves a chain of like LPs: the same subproblem
//! again with the rows its solution violated added (the active set), and the next iterate's,
//! whose rows are the same up to the jerk rows' tangents and whose objective is the time's
//! gradient at the new point. Each may start from the last one's primal z and multipliers
//! (returned per row, in the rows' own units, so that another equilibration can read them).
//! The last solution lies on the boundary (s = 0 on a binding row, λ = 0 on a slack one),
//! where an interior-point method cannot start, so every pair is moved the least that makes
//! `s λ = WARM_MU` without either moving by more than √WARM_MU: a binding row keeps its λ and
//! takes s = μ/λ, a slack one keeps its s and takes λ = μ/s, a row with both small (or one
//! the last problem did not have, and that its z violates) takes √μ for both. A start from a
//! profile alone (a warm profile of a refinement: z known, no multipliers) takes the same
//! rule with every λ unknown. A warm start that does not converge is tried again cold, so the
//! answer never depends on it: the stopping rule is the same. Measured on the 20 COPP paths
//! with jerk limits (one core, the CLI, alternating runs, 2026-11-27): 7.8 s → 5.75 s for the
//! twenty; on paths 3, 10, 15 and 18, 1,164, 1,330, 1,201 and 1,141 interior-point iterations
//! → 727, 857, 746 and 677; the same cycle times to 2.5e-6 (path 0, inside the SCP's
//! tolerance). `WARM_MU` of 1e-3 and 3e-2 took 2–8 % more iterations than 1e-2, 1e-4 and 1e-1
//! 15–30 % more.

use super::Rows;

/// Largest half-bandwidth the solver takes; a wider problem is left to Clarabel.
const MAX_BANDWIDTH: usize = 24;
/// Interior-point iterations before giving up (Clarabel's answer is then asked for).
const MAX_ITER: usize = 80;
/// Static regularisation of the KKT matrix: ρ on the columns' diagonal and −δ on the
/// equalities' (rows and columns equilibrated). As Clarabel's, it is absolute:
/// relative to the largest diagonal entry, which grows without bound as rows become active, it
/// would swamp the other columns near the optimum.
const STATIC_REG: f64 = 1e-9;
/// −δ on the equalities' diagonal of the scaled KKT matrix (pivots there are of order one).
const EQ_REG: f64 = 1e-12;
/// A pivot of magnitude below this is replaced by it, with the sign it should have.
const DYNAMIC_REG: f64 = 1e-13;
/// Fraction of the step to the boundary of the positive orthant taken.
const STEP_FRACTION: f64 = 0.99;
/// A row's rounding allowance, relative to the sum of its terms' magnitudes ([`Lp::rows_hold`]).
const TERMS_TOL: f64 = 1e-13;
/// Passes of Ruiz equilibration of the rows and columns. Four give the jerk subproblems the
/// same iterates as ten did (the same interior-point iterations on the COPP paths, 2026-11-27),
/// for less of an LP's set-up, which the warm starts made a larger share of its time. Two (once
/// most windows needed no local refinement, stop 41): the 20 COPP paths with jerk limits took
/// 15,675 interior-point iterations against 15,670 and the same cycle times, for 3.5–3.7 %
/// fewer instructions (paths 3, 10); the jerk-limited impeller 37,228 against 37,627, the same
/// four LPs left to Clarabel, 4e-6 shorter. (One pass: 15,682 and −5 %, kept at two for the
/// problems whose rows span more orders of magnitude.)
const RUIZ_PASSES: usize = 2;
/// Entries per row of the products' unrolled form ([`Lp`]).
const WIDTH: usize = 4;
/// Steps of iterative refinement per KKT solve (the corrector's and the cold start's; the
/// predictor's has none).
const REFINE: usize = 1;
/// A warm start's products s λ (scaled problem).
const WARM_MU: f64 = 1e-2;

/// Why the banded solver did not answer (the caller then asks Clarabel).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Unsolved {
    /// Half-bandwidth over [`MAX_BANDWIDTH`].
    NotBanded(usize),
    /// No convergence within [`MAX_ITER`] iterations (infeasible, unbounded or ill-posed).
    NoConvergence,
    /// A non-finite value appeared.
    NotFinite,
}

/// The answer: the primal solution, every row's multiplier and the iterations it took.
#[derive(Debug, Clone)]
pub(crate) struct LpSolution {
    pub x: Vec<f64>,
    /// Per row, in the problem's own units: ν of an equality, λ ≥ 0 of an inequality
    /// (`q + Σ_r y_r a_r = 0` at the optimum). A warm start of a like problem reads them.
    pub duals: Vec<f64>,
    pub iterations: u32,
}

/// A starting point from the solution of a like problem ([`solve`]): its primal, and per row of
/// the new problem the multiplier it had there (NaN: a row it did not have).
pub(crate) struct WarmStart<'a> {
    pub x: &'a [f64],
    pub duals: &'a [f64],
}

/// The problem with rows scaled, in row-major form, every row `width` entries long.
///
/// A shorter row is padded with zero coefficients on its first column: they add nothing to a
/// product, a maximum of magnitudes or the KKT matrix ([`Kkt::pairs`] skips them), so every
/// value is the one of the unpadded rows, and the products with A, which an iteration computes
/// six times, run without a loop per row where rows are at most four entries long (the jerk
/// subproblems': 80 % of their rows have four entries, the others one or two).
struct Lp {
    /// Columns.
    n: usize,
    /// Entries per row: the longest row's length, at least [`WIDTH`].
    width: usize,
    /// Row `r` has the entries `r * width..(r + 1) * width` of `col`, `val`.
    col: Vec<usize>,
    val: Vec<f64>,
    /// The same entries column by column (without the padding), each column's in row order:
    /// column `j` has `t_start[j]..t_start[j + 1]` of `t_row`, `t_val` ([`Lp::transpose`]).
    t_start: Vec<usize>,
    t_row: Vec<u32>,
    t_val: Vec<f64>,
    /// Right-hand sides: the first `n_eq` rows are equalities, the others `≤`.
    rhs: Vec<f64>,
    n_eq: usize,
    q: Vec<f64>,
}

impl Lp {
    fn rows(&self) -> usize {
        self.rhs.len()
    }

    fn entries(&self, r: usize) -> std::ops::Range<usize> {
        r * self.width..(r + 1) * self.width
    }

    /// `out[r] = (A z)_r` for every row.
    fn mul(&self, z: &[f64], out: &mut [f64]) {
        if self.width == WIDTH {
            let rows = self
                .col
                .chunks_exact(WIDTH)
                .zip(self.val.chunks_exact(WIDTH));
            for (o, (c, v)) in out.iter_mut().zip(rows) {
                *o = v[0] * z[c[0]] + v[1] * z[c[1]] + v[2] * z[c[2]] + v[3] * z[c[3]];
            }
        } else {
            for (r, o) in out.iter_mut().enumerate() {
                *o = self.entries(r).map(|t| self.val[t] * z[self.col[t]]).sum();
            }
        }
    }

    /// Every row holds at `z` in its own units: `|a·z − h|` (an equality) or `a·z − h` (an
    /// inequality) at most `tol |h|` plus [`TERMS_TOL`] of `Σ|a_j z_j|` (rounding). Invariant
    /// under the scaling of rows and columns. Relative to the terms alone it was not enough:
    /// a jerk row over a short interval is a small difference of terms a million times its
    /// bound (coefficients in 1/Δu³), so 1e-8 of the terms let the jerk between the LP's sites
    /// exceed its limit by percents, and the local refinement, dividing those intervals
    /// further, made it worse round after round (the jerk-limited impeller's rest ends).
    fn rows_hold(&self, z: &[f64], tol: f64) -> bool {
        (0..self.rows()).all(|r| {
            let (mut a, mut abs) = (0.0, 0.0);
            for t in self.entries(r) {
                let v = self.val[t] * z[self.col[t]];
                a += v;
                abs += v.abs();
            }
            let h = self.rhs[r];
            let viol = if r < self.n_eq { (a - h).abs() } else { a - h };
            viol <= tol * h.abs() + TERMS_TOL * abs
        })
    }

    /// `out = Aᵀ y` (`out` overwritten), column by column: each sum in row order, as adding
    /// the rows' multiples one after the other would give it, without the chain of stores and
    /// loads that makes through the same few columns.
    fn mul_t(&self, y: &[f64], out: &mut [f64]) {
        for (j, o) in out.iter_mut().enumerate() {
            let es = self.t_start[j]..self.t_start[j + 1];
            *o = self.t_row[es.clone()]
                .iter()
                .zip(&self.t_val[es])
                .fold(0.0, |acc, (&r, &v)| acc + v * y[r as usize]);
        }
    }

    /// Fills the column-by-column copy of the entries ([`Lp::mul_t`]); after the scaling.
    fn transpose(&mut self) {
        let mut count = vec![0usize; self.n + 1];
        for (&c, &v) in self.col.iter().zip(&self.val) {
            if v != 0.0 {
                count[c + 1] += 1;
            }
        }
        for j in 0..self.n {
            count[j + 1] += count[j];
        }
        self.t_start.clone_from(&count);
        let nnz = count[self.n];
        self.t_row.resize(nnz, 0);
        self.t_val.resize(nnz, 0.0);
        for (t, (&c, &v)) in self.col.iter().zip(&self.val).enumerate() {
            if v != 0.0 {
                let at = count[c];
                self.t_row[at] = (t / self.width) as u32;
                self.t_val[at] = v;
                count[c] += 1;
            }
        }
    }
}

/// The banded KKT matrix: positions of the columns and equality multipliers, and the
/// factorisation's storage.
struct Kkt {
    /// Position of column j in the ordering.
    pos_col: Vec<usize>,
    /// Position of equality row e.
    pos_eq: Vec<usize>,
    /// Half-bandwidth.
    bw: usize,
    /// Size (columns + equalities).
    size: usize,
    /// `band[i * (bw + 1) + d]`: K(i, i − d) before factorising, L(i, i − d) (d > 0) and D(i)
    /// (d = 0) after.
    band: Vec<f64>,
    /// +1 at a column's position, −1 at an equality's: the sign the pivot must have.
    sign: Vec<f64>,
    /// Scratch of the factorisation: L(i, k) D(k).
    ld: Vec<f64>,
    /// The symmetric diagonal scaling of K per position ([`Kkt::factor`]).
    scale: Vec<f64>,
    /// The scaled K without its regularisation, in band storage.
    k0: Vec<f64>,
    /// Per place in the band, the inequality rows whose coefficient products add there:
    /// `pairs[pair_start[i]..pair_start[i + 1]]` of (row, product) ([`Kkt::pairs`]).
    pair_start: Vec<usize>,
    pairs: Vec<(u32, f64)>,
}

impl Kkt {
    fn new(lp: &Lp) -> Result<Kkt, Unsolved> {
        // Each equality right after its last column, in that column's order.
        let mut last: Vec<(usize, usize)> = (0..lp.n_eq)
            .map(|e| {
                let m = lp.entries(e).map(|t| lp.col[t]).max().unwrap_or(0);
                (m, e)
            })
            .collect();
        last.sort_unstable();
        let size = lp.n + lp.n_eq;
        let (mut pos_col, mut pos_eq) = (vec![0; lp.n], vec![0; lp.n_eq]);
        let mut sign = Vec::with_capacity(size);
        let mut next = 0;
        let mut eqs = last.iter().peekable();
        for (j, p) in pos_col.iter_mut().enumerate() {
            *p = next;
            next += 1;
            sign.push(1.0);
            while let Some(&(_, e)) = eqs.next_if(|(m, _)| *m <= j) {
                pos_eq[e] = next;
                next += 1;
                sign.push(-1.0);
            }
        }
        for &(_, e) in eqs {
            pos_eq[e] = next;
            next += 1;
            sign.push(-1.0);
        }
        let mut bw = 0;
        for r in 0..lp.rows() {
            let ps = lp.entries(r).map(|t| pos_col[lp.col[t]]);
            let (lo, hi) = ps.fold((usize::MAX, 0), |(a, b), p| (a.min(p), b.max(p)));
            if lo == usize::MAX {
                continue;
            }
            let hi = if r < lp.n_eq { pos_eq[r] } else { hi };
            bw = bw.max(hi - lo);
        }
        if bw > MAX_BANDWIDTH {
            return Err(Unsolved::NotBanded(bw));
        }
        let mut kkt = Kkt {
            pos_col,
            pos_eq,
            bw,
            size,
            band: vec![0.0; size * (bw + 1)],
            sign,
            ld: vec![0.0; bw + 1],
            scale: vec![1.0; size],
            k0: Vec::new(),
            pair_start: Vec::new(),
            pairs: Vec::new(),
        };
        kkt.pairs(lp);
        Ok(kkt)
    }

    fn at(&mut self, i: usize, j: usize) -> &mut f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        &mut self.band[i * (self.bw + 1) + (i - j)]
    }

    /// Which inequality rows' products of coefficients add at each place of the band, place by
    /// place, each place's in row order (a stable counting sort of the products as the rows
    /// give them): [`Kkt::factor`] then sums each place's in the order adding the rows one
    /// after the other would, without the chain of stores and loads that makes.
    fn pairs(&mut self, lp: &Lp) {
        let s1 = self.bw + 1;
        // (Place, inequality row, product), row by row.
        let mut products: Vec<(u32, u32, f64)> = Vec::new();
        for r in lp.n_eq..lp.rows() {
            let es = lp.entries(r);
            // (Not the padding: a zero coefficient adds nothing.)
            for a in es.clone().filter(|&a| lp.val[a] != 0.0) {
                let pa = self.pos_col[lp.col[a]];
                for b in (es.start..=a).filter(|&b| lp.val[b] != 0.0) {
                    let pb = self.pos_col[lp.col[b]];
                    let v = lp.val[a] * lp.val[b];
                    // A repeated column's diagonal pair counts twice off the diagonal only.
                    let v = if a != b && pa == pb { 2.0 * v } else { v };
                    let (i, j) = if pa >= pb { (pa, pb) } else { (pb, pa) };
                    products.push(((i * s1 + (i - j)) as u32, (r - lp.n_eq) as u32, v));
                }
            }
        }
        let mut count = vec![0usize; self.band.len() + 1];
        for &(at, _, _) in &products {
            count[at as usize + 1] += 1;
        }
        for i in 0..self.band.len() {
            count[i + 1] += count[i];
        }
        self.pair_start.clone_from(&count);
        self.pairs.clear();
        self.pairs.resize(products.len(), (0, 0.0));
        for &(at, r, v) in &products {
            self.pairs[count[at as usize]] = (r, v);
            count[at as usize] += 1;
        }
    }

    /// Fills and factorises K for inequality weights `w` (one per inequality row), with ρ =
    /// [`STATIC_REG`] and δ = [`EQ_REG`].
    fn factor(&mut self, lp: &Lp, w: &[f64]) {
        let (rho, delta) = (STATIC_REG, EQ_REG);
        for (at, b) in self.band.iter_mut().enumerate() {
            *b = self.pairs[self.pair_start[at]..self.pair_start[at + 1]]
                .iter()
                .fold(0.0, |acc, &(r, v)| acc + w[r as usize] * v);
        }
        for j in 0..lp.n {
            let p = self.pos_col[j];
            *self.at(p, p) += rho;
        }
        for e in 0..lp.n_eq {
            let pe = self.pos_eq[e];
            for t in lp.entries(e) {
                let pc = self.pos_col[lp.col[t]];
                *self.at(pe, pc) += lp.val[t];
            }
        }
        // Symmetric diagonal scaling: unit diagonal on the columns, and each equality's row of
        // the scaled E of unit norm, so that its pivot (−E H⁻¹ Eᵀ, tiny where the active rows'
        // weights are huge) is of order one; then −δ on the equalities' diagonal.
        let s1 = self.bw + 1;
        for j in 0..lp.n {
            let p = self.pos_col[j];
            self.scale[p] = 1.0 / self.band[p * s1].sqrt();
        }
        for e in 0..lp.n_eq {
            let pe = self.pos_eq[e];
            let norm: f64 = lp
                .entries(e)
                .map(|t| (lp.val[t] * self.scale[self.pos_col[lp.col[t]]]).powi(2))
                .sum::<f64>()
                .sqrt();
            self.scale[pe] = if norm > 0.0 { 1.0 / norm } else { 1.0 };
        }
        for i in 0..self.size {
            for d in 0..=self.bw.min(i) {
                self.band[i * s1 + d] *= self.scale[i] * self.scale[i - d];
            }
        }
        for e in 0..lp.n_eq {
            let pe = self.pos_eq[e];
            self.band[pe * s1] = -delta;
        }
        // K₀ (scaled), for the refinement: without the regularisation.
        self.k0.clone_from(&self.band);
        for j in 0..lp.n {
            let p = self.pos_col[j];
            self.k0[p * s1] -= rho * self.scale[p] * self.scale[p];
        }
        for e in 0..lp.n_eq {
            self.k0[self.pos_eq[e] * s1] = 0.0;
        }
        // LDLᵀ in the band, row by row.
        let (bw, s) = (self.bw, self.bw + 1);
        let eps = DYNAMIC_REG;
        for i in 0..self.size {
            let k0 = i.saturating_sub(bw);
            for j in k0..i {
                let mut v = self.band[i * s + (i - j)];
                for k in k0.max(j.saturating_sub(bw))..j {
                    v -= self.ld[k - k0] * self.band[j * s + (j - k)];
                }
                self.ld[j - k0] = v;
                let dj = self.band[j * s];
                self.band[i * s + (i - j)] = v / dj;
            }
            let mut d = self.band[i * s];
            for k in k0..i {
                d -= self.ld[k - k0] * self.band[i * s + (i - k)];
            }
            if d * self.sign[i] < eps {
                d = self.sign[i] * eps;
            }
            self.band[i * s] = d;
        }
    }

    /// Solves K v = b in place (b in position order).
    fn solve(&self, v: &mut [f64]) {
        let s = self.bw + 1;
        for (x, c) in v.iter_mut().zip(&self.scale) {
            *x *= c;
        }
        for i in 0..self.size {
            let k0 = i.saturating_sub(self.bw);
            let mut x = v[i];
            for k in k0..i {
                x -= self.band[i * s + (i - k)] * v[k];
            }
            v[i] = x;
        }
        for i in 0..self.size {
            v[i] /= self.band[i * s];
        }
        for i in (0..self.size).rev() {
            let x = v[i];
            if x != 0.0 {
                let k0 = i.saturating_sub(self.bw);
                for k in k0..i {
                    v[k] -= self.band[i * s + (i - k)] * x;
                }
            }
        }
        for (x, c) in v.iter_mut().zip(&self.scale) {
            *x *= c;
        }
    }
}

/// The KKT system of one iteration, with the scratch of its solves.
struct Newton<'a> {
    lp: &'a Lp,
    kkt: Kkt,
    /// W = λ/s per inequality.
    w: Vec<f64>,
    rhs: Vec<f64>,
    sol: Vec<f64>,
    res: Vec<f64>,
    cols: Vec<f64>,
}

impl Newton<'_> {
    /// `out = K₀ v` with the unregularised K₀, in position order: `S⁻¹ (S K₀ S) S⁻¹ v` from
    /// the band.
    fn apply(&mut self, v: &[f64], out: &mut [f64]) {
        let kkt = &self.kkt;
        let (bw, s1) = (kkt.bw, kkt.bw + 1);
        self.cols.clear();
        self.cols
            .extend(v.iter().zip(&kkt.scale).map(|(x, c)| x / c));
        let w = &self.cols;
        out.fill(0.0);
        for i in 0..kkt.size {
            let row = &kkt.k0[i * s1..(i + 1) * s1];
            let mut acc = row[0] * w[i];
            for d in 1..=bw.min(i) {
                acc += row[d] * w[i - d];
                out[i - d] += row[d] * w[i];
            }
            out[i] += acc;
        }
        for (o, c) in out.iter_mut().zip(&kkt.scale) {
            *o /= c;
        }
    }

    /// Solves [GᵀWG Eᵀ; E 0](dz, dnu) = (a, b) (a per column, b per equality), with `refine`
    /// steps of refinement.
    fn solve(&mut self, a: &[f64], b: &[f64], dz: &mut [f64], dnu: &mut [f64], refine: usize) {
        let (lp, size) = (self.lp, self.kkt.size);
        self.rhs.resize(size, 0.0);
        for j in 0..lp.n {
            self.rhs[self.kkt.pos_col[j]] = a[j];
        }
        for e in 0..lp.n_eq {
            self.rhs[self.kkt.pos_eq[e]] = b[e];
        }
        self.sol.clone_from(&self.rhs);
        self.kkt.solve(&mut self.sol);
        let mut res = std::mem::take(&mut self.res);
        res.resize(size, 0.0);
        let mut sol = std::mem::take(&mut self.sol);
        for _ in 0..refine {
            self.apply(&sol, &mut res);
            for (r, b) in res.iter_mut().zip(&self.rhs) {
                *r = b - *r;
            }
            self.kkt.solve(&mut res);
            for (s, r) in sol.iter_mut().zip(&res) {
                *s += r;
            }
        }
        self.sol = sol;
        self.res = res;
        for j in 0..lp.n {
            dz[j] = self.sol[self.kkt.pos_col[j]];
        }
        for e in 0..lp.n_eq {
            dnu[e] = self.sol[self.kkt.pos_eq[e]];
        }
    }
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The largest α ≤ 1 with v + α dv ≥ 0 (v > 0), times [`STEP_FRACTION`] when it binds.
fn step_to_boundary(v: &[f64], dv: &[f64]) -> f64 {
    // α only falls, so a division is needed only where the bound is met first.
    let mut alpha: f64 = 1.0 / STEP_FRACTION;
    for (&x, &d) in v.iter().zip(dv) {
        if x + alpha * d < 0.0 {
            alpha = -x / d;
        }
    }
    (alpha * STEP_FRACTION).min(1.0)
}

/// Minimises `q·z` subject to the rows of `rows`: the first `n_eq` are equalities `a·z = h`,
/// the others `a·z ≤ h`. Stops as Clarabel does at `tol_feas` and `tol_gap` (module doc).
/// From `warm` where given (module doc), and from the cold start where that does not converge.
pub(crate) fn solve(
    q: &[f64],
    rows: &Rows,
    n_eq: usize,
    tol_feas: f64,
    tol_gap: f64,
    warm: Option<&WarmStart>,
) -> Result<LpSolution, Unsolved> {
    if let Some(w) = warm {
        match solve_from(q, rows, n_eq, tol_feas, tol_gap, Some(w)) {
            Ok(sol) => return Ok(sol),
            Err(Unsolved::NotBanded(bw)) => return Err(Unsolved::NotBanded(bw)),
            Err(e) => tracing::trace!("banded LP: warm start {e:?}; cold"),
        }
    }
    solve_from(q, rows, n_eq, tol_feas, tol_gap, None)
}

/// [`solve`] from a warm start, or from CVXOPT's cold one.
fn solve_from(
    q: &[f64],
    rows: &Rows,
    n_eq: usize,
    tol_feas: f64,
    tol_gap: f64,
    warm: Option<&WarmStart>,
) -> Result<LpSolution, Unsolved> {
    let n = q.len();
    // Rows scaled to unit largest coefficient (before Ruiz's passes below; they start from
    // it), each padded to `width` entries.
    let width = (0..rows.len())
        .map(|r| rows.triplets(r).len())
        .fold(WIDTH, usize::max);
    let mut lp = Lp {
        n,
        width,
        col: Vec::with_capacity(rows.len() * width),
        val: Vec::with_capacity(rows.len() * width),
        t_start: Vec::new(),
        t_row: Vec::new(),
        t_val: Vec::new(),
        rhs: Vec::with_capacity(rows.len()),
        n_eq,
        q: q.to_vec(),
    };
    // Each row's scale factor, all passes together: row r of the scaled problem is
    // `row_scale[r]` times the given one (with the columns scaled).
    let mut row_scale = Vec::with_capacity(rows.len());
    for r in 0..rows.len() {
        let ts = rows.triplets(r);
        let big = ts.clone().fold(0.0_f64, |m, t| m.max(rows.v[t].abs()));
        let scale = if big > 0.0 { 1.0 / big } else { 1.0 };
        row_scale.push(scale);
        let first = ts.clone().next().map_or(0, |t| rows.j[t]);
        let len = ts.len();
        for t in ts {
            lp.col.push(rows.j[t]);
            lp.val.push(rows.v[t] * scale);
        }
        for _ in len..width {
            lp.col.push(first);
            lp.val.push(0.0);
        }
        lp.rhs.push(rows.h[r] * scale);
    }
    // Ruiz equilibration (as Clarabel's): rows and columns scaled alternately towards unit
    // largest coefficient, z = C ẑ; then the objective to unit largest coefficient (`cost`).
    let mut col_scale = vec![1.0; n];
    let mut col_big = vec![0.0_f64; n];
    for _ in 0..RUIZ_PASSES {
        col_big.fill(0.0);
        for t in 0..lp.val.len() {
            col_big[lp.col[t]] = col_big[lp.col[t]].max(lp.val[t].abs());
        }
        for r in 0..lp.rows() {
            let es = lp.entries(r);
            let big = es.clone().fold(0.0_f64, |m, t| m.max(lp.val[t].abs()));
            let d = if big > 0.0 { 1.0 / big.sqrt() } else { 1.0 };
            for t in es {
                lp.val[t] *= d;
            }
            lp.rhs[r] *= d;
            row_scale[r] *= d;
        }
        for (c, big) in col_scale.iter_mut().zip(&mut col_big) {
            *big = if *big > 0.0 { 1.0 / big.sqrt() } else { 1.0 };
            *c *= *big;
        }
        for t in 0..lp.val.len() {
            lp.val[t] *= col_big[lp.col[t]];
        }
    }
    for (qj, c) in lp.q.iter_mut().zip(&col_scale) {
        *qj *= c;
    }
    let cost = match norm_inf(&lp.q) {
        big if big > 0.0 => 1.0 / big,
        _ => 1.0,
    };
    for qj in &mut lp.q {
        *qj *= cost;
    }
    lp.transpose();
    let m = lp.rows() - n_eq;
    let kkt = Kkt::new(&lp)?;
    let (h, f) = (&lp.rhs[n_eq..], &lp.rhs[..n_eq]);
    let (norm_h, norm_f, norm_q) = (norm_inf(h), norm_inf(f), norm_inf(&lp.q));

    let mut nt = Newton {
        lp: &lp,
        kkt,
        w: vec![1.0; m],
        rhs: Vec::new(),
        sol: Vec::new(),
        res: Vec::new(),
        cols: vec![0.0; n],
    };
    let (mut z, mut nu) = (vec![0.0; n], vec![0.0; n_eq]);
    let (mut s, mut lam) = (vec![0.0; m], vec![0.0; m]);
    let mut ax = vec![0.0; lp.rows()];
    let mut col = vec![0.0; n];

    if let Some(w) = warm {
        // From a like problem's solution: z as it was and ν as it was (scaled as this problem
        // is); every row's slack there and its λ, the smaller of the two raised so that their
        // product is WARM_MU: a centred point, as near the boundary as the old solution is.
        for j in 0..n {
            z[j] = w.x[j] / col_scale[j];
        }
        lp.mul(&z, &mut ax);
        for e in 0..n_eq {
            let v = w.duals[e] * cost / row_scale[e];
            nu[e] = if v.is_finite() { v } else { 0.0 };
        }
        let mu_t = WARM_MU;
        for i in 0..m {
            let si = (h[i] - ax[n_eq + i]).max(0.0);
            let li = w.duals[n_eq + i] * cost / row_scale[n_eq + i];
            let li = if li.is_finite() { li.max(0.0) } else { 0.0 };
            // Neither moves by more than √μ: a row binding (λ ≥ √μ) keeps λ, one slack
            // (s ≥ √μ) keeps s, one with both small takes √μ for both.
            let root = mu_t.sqrt();
            (s[i], lam[i]) = if si * li >= mu_t {
                (si, li)
            } else if li >= root {
                (mu_t / li, li)
            } else if si >= root {
                (si, mu_t / si)
            } else {
                (root, root)
            };
        }
    } else {
        // Starting point (CVXOPT): z minimises |G z − h|² subject to E z = f, s = h − G z; λ is
        // the least-norm dual G w with Gᵀ(G w) + Eᵀ ν = −q, E w = 0; both shifted into the interior.
        nt.kkt.factor(&lp, &nt.w);
        {
            let mut hg = vec![0.0; lp.rows()];
            hg[n_eq..].copy_from_slice(h);
            lp.mul_t(&hg, &mut col);
            nt.solve(&col, f, &mut z, &mut nu, REFINE);
            lp.mul(&z, &mut ax);
            for i in 0..m {
                s[i] = h[i] - ax[n_eq + i];
            }
            let neg_q: Vec<f64> = lp.q.iter().map(|v| -v).collect();
            let zero = vec![0.0; n_eq];
            let mut wv = vec![0.0; n];
            nt.solve(&neg_q, &zero, &mut wv, &mut nu, REFINE);
            lp.mul(&wv, &mut ax);
            lam.copy_from_slice(&ax[n_eq..]);
            // Mehrotra's shift (Nocedal & Wright, §14.2): into the positive orthant, then
            // both by half the complementarity over the other's sum, so no product is small.
            if m > 0 {
                for v in [&mut s, &mut lam] {
                    let lowest = v.iter().fold(f64::INFINITY, |a, &b| a.min(b));
                    let shift = (-1.5 * lowest).max(0.0);
                    for x in v.iter_mut() {
                        *x += shift;
                    }
                }
                let sl = dot(&s, &lam);
                let (sum_s, sum_l): (f64, f64) = (s.iter().sum(), lam.iter().sum());
                let (ds, dl) = (0.5 * sl / sum_l, 0.5 * sl / sum_s);
                for x in &mut s {
                    *x += if ds.is_finite() { ds } else { 1.0 };
                }
                for x in &mut lam {
                    *x += if dl.is_finite() { dl } else { 1.0 };
                }
                // A start at the origin of both (no rows bind any variable): unit values.
                for v in [&mut s, &mut lam] {
                    for x in v.iter_mut() {
                        if x.is_nan() || *x <= 0.0 {
                            *x = 1.0;
                        }
                    }
                }
            }
        }
    }

    let mut r_d = vec![0.0; n];
    let mut r_p = vec![0.0; m];
    let mut r_e = vec![0.0; n_eq];
    let (mut dz, mut dnu) = (vec![0.0; n], vec![0.0; n_eq]);
    let (mut ds, mut dl) = (vec![0.0; m], vec![0.0; m]);
    let (mut dz_a, mut dnu_a) = (vec![0.0; n], vec![0.0; n_eq]);
    let (mut ds_a, mut dl_a) = (vec![0.0; m], vec![0.0; m]);
    let mut r_c = vec![0.0; m];
    let mut y = vec![0.0; lp.rows()];
    let mut a_rhs = vec![0.0; n];
    let mut t = vec![0.0; lp.rows()];
    let mut neg_r_e = vec![0.0; n_eq];

    let mut best_merit = f64::INFINITY;
    let mut inv_s = vec![0.0; m];
    for it in 0..MAX_ITER {
        // Residuals.
        y[..n_eq].copy_from_slice(&nu);
        y[n_eq..].copy_from_slice(&lam);
        lp.mul_t(&y, &mut r_d);
        for (r, qv) in r_d.iter_mut().zip(&lp.q) {
            *r += qv;
        }
        lp.mul(&z, &mut ax);
        // (The loops over rows zipped, not indexed: without bounds checks they vectorise; the
        // same operations on each element, so the same values.)
        for (((r, a), s), h) in r_p.iter_mut().zip(&ax[n_eq..]).zip(&s).zip(h) {
            *r = a + s - h;
        }
        for e in 0..n_eq {
            r_e[e] = ax[e] - f[e];
            neg_r_e[e] = -r_e[e];
        }
        let norm_z = norm_inf(&z);
        let pres = norm_inf(&r_p).max(norm_inf(&r_e)) / (1.0 + norm_h.max(norm_f).max(norm_z));
        let dres = norm_inf(&r_d) / (1.0 + norm_q);
        let gap = dot(&s, &lam);
        let pobj = dot(&lp.q, &z);
        let dobj = -dot(h, &lam) - dot(f, &nu);
        if !(gap.is_finite() && pres.is_finite() && dres.is_finite()) {
            return Err(Unsolved::NotFinite);
        }
        if pres <= tol_feas
            && dres <= tol_feas
            && (gap <= tol_gap * cost || gap <= tol_gap * pobj.abs().min(dobj.abs()))
            && lp.rows_hold(&z, tol_feas)
        {
            let duals = nu
                .iter()
                .chain(&lam)
                .zip(&row_scale)
                .map(|(y, r)| y * r / cost)
                .collect();
            return Ok(LpSolution {
                x: z.iter().zip(&col_scale).map(|(z, c)| z * c).collect(),
                duals,
                iterations: it as u32,
            });
        }
        // Past the tolerances the rounding of a KKT solve near the optimum can throw an iterate
        // off (W = λ/s spans 40 orders of magnitude there): an iteration that makes the worst
        // residual a hundred times worse than the best so far ends the attempt.
        let merit = pres.max(dres).max(gap / (1.0 + pobj.abs().min(dobj.abs())));
        if merit > 100.0 * best_merit.max(tol_feas) && it > 0 {
            return Err(Unsolved::NoConvergence);
        }
        best_merit = best_merit.min(merit);
        let mu = if m > 0 { gap / m as f64 } else { 0.0 };

        for (((inv, w), s), l) in inv_s.iter_mut().zip(&mut nt.w).zip(&s).zip(&lam) {
            *inv = 1.0 / s;
            *w = l * *inv;
        }
        nt.kkt.factor(&lp, &nt.w);

        // One Newton solve for the complementarity right-hand side r_c:
        // GᵀWG dz + Eᵀ dν = −r_d − Gᵀ S⁻¹(Λ r_p − r_c), E dz = −r_e;
        // ds = −r_p − G dz; dλ = S⁻¹(−r_c − Λ ds); `refine` steps of refinement.
        let mut newton = |r_c: &[f64],
                          refine: usize,
                          nt: &mut Newton,
                          dz: &mut [f64],
                          dnu: &mut [f64],
                          ds: &mut [f64],
                          dl: &mut [f64]| {
            t[..n_eq].fill(0.0);
            for ((((t, l), r), c), inv) in t[n_eq..]
                .iter_mut()
                .zip(&lam)
                .zip(&r_p)
                .zip(r_c)
                .zip(&inv_s)
            {
                *t = (l * r - c) * inv;
            }
            lp.mul_t(&t, &mut a_rhs);
            for (a, r) in a_rhs.iter_mut().zip(&r_d) {
                *a = -r - *a;
            }
            nt.solve(&a_rhs, &neg_r_e, dz, dnu, refine);
            lp.mul(dz, &mut t);
            for (((((ds, dl), r), t), c), (l, inv)) in ds
                .iter_mut()
                .zip(dl.iter_mut())
                .zip(&r_p)
                .zip(&t[n_eq..])
                .zip(r_c)
                .zip(lam.iter().zip(&inv_s))
            {
                *ds = -r - t;
                *dl = (-c - l * *ds) * inv;
            }
        };

        // Predictor (affine scaling). Unrefined: it only sets the centring σ and the
        // corrector's second-order term, and refining it did not change one iteration's count
        // on the 20 COPP paths with jerk limits (15,328 with, 15,332 without, the same cycle
        // times), while it costs a product with K₀ and a band solve per iteration.
        for ((c, s), l) in r_c.iter_mut().zip(&s).zip(&lam) {
            *c = s * l;
        }
        newton(
            &r_c, 0, &mut nt, &mut dz_a, &mut dnu_a, &mut ds_a, &mut dl_a,
        );
        let (ap, ad) = (step_to_boundary(&s, &ds_a), step_to_boundary(&lam, &dl_a));
        let mu_aff = if m > 0 {
            s.iter()
                .zip(&ds_a)
                .zip(lam.iter().zip(&dl_a))
                .map(|((s, ds), (l, dl))| (s + ap * ds) * (l + ad * dl))
                .sum::<f64>()
                / m as f64
        } else {
            0.0
        };
        let sigma = if mu > 0.0 {
            (mu_aff / mu).clamp(0.0, 1.0).powi(3)
        } else {
            0.0
        };
        // Corrector (centring and second order).
        for ((((c, s), l), da), la) in r_c.iter_mut().zip(&s).zip(&lam).zip(&ds_a).zip(&dl_a) {
            *c = s * l + da * la - sigma * mu;
        }
        newton(&r_c, REFINE, &mut nt, &mut dz, &mut dnu, &mut ds, &mut dl);
        let (ap, ad) = (step_to_boundary(&s, &ds), step_to_boundary(&lam, &dl));
        for (z, d) in z.iter_mut().zip(&dz) {
            *z += ap * d;
        }
        for (s, d) in s.iter_mut().zip(&ds) {
            *s += ap * d;
        }
        for (l, d) in lam.iter_mut().zip(&dl) {
            *l += ad * d;
        }
        for (v, d) in nu.iter_mut().zip(&dnu) {
            *v += ad * d;
        }
    }
    Err(Unsolved::NoConvergence)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SupportedConeT};

    /// Clarabel's solution of the same LP.
    fn clarabel(q: &[f64], rows: &Rows, n_eq: usize) -> Vec<f64> {
        let a = CscMatrix::new_from_triplets(
            rows.len(),
            q.len(),
            rows.i.clone(),
            rows.j.clone(),
            rows.v.clone(),
        );
        let p = CscMatrix::zeros((q.len(), q.len()));
        let mut cones = vec![SupportedConeT::NonnegativeConeT(rows.len() - n_eq)];
        if n_eq > 0 {
            cones.insert(0, SupportedConeT::ZeroConeT(n_eq));
        }
        let s = DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(1e-10)
            .tol_gap_rel(1e-10)
            .build()
            .unwrap();
        let mut solver = DefaultSolver::new(&p, q, &a, &rows.h, &cones, s).unwrap();
        solver.solve();
        solver.solution.x.clone()
    }

    /// A deterministic pseudo-random number in [−1, 1).
    fn rnd(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// A profile-like LP: x_i ≤ 1 + (random), coupling rows between neighbours that hold at a
    /// known interior point, the objective pushing every x up; `eq` equalities
    /// x_{i+1} − x_i − (y_i + y_{i+1}) = c through that point.
    fn banded_lp(n: usize, seed: u64, eq: bool) -> (Vec<f64>, Rows, usize) {
        let mut st = seed;
        let nv = 2 * n;
        let x0: Vec<f64> = (0..nv).map(|_| 0.5 + 0.2 * rnd(&mut st)).collect();
        let mut rows = Rows::default();
        let mut n_eq = 0;
        if eq {
            for i in 0..n - 1 {
                let c = [
                    (2 * i + 2, 1.0),
                    (2 * i, -1.0),
                    (2 * i + 1, -0.3),
                    (2 * i + 3, -0.3),
                ];
                let h = c.iter().map(|&(j, v)| v * x0[j]).sum();
                rows.push(&c, h);
                n_eq += 1;
            }
        }
        for j in 0..nv {
            rows.push(&[(j, 1.0)], x0[j] + 0.3 + 0.2 * rnd(&mut st).abs());
            rows.push(&[(j, -1.0)], 5.0);
        }
        for i in 0..n - 1 {
            for _ in 0..3 {
                let c: Vec<(usize, f64)> = (2 * i..2 * i + 4)
                    .map(|j| (j, 3.0 * rnd(&mut st)))
                    .collect();
                let h: f64 = c.iter().map(|&(j, v)| v * x0[j]).sum::<f64>()
                    + 0.05
                    + 0.5 * rnd(&mut st).abs();
                rows.push(&c, h);
            }
        }
        let q: Vec<f64> = (0..nv)
            .map(|j| if j % 2 == 0 { -1.0 } else { 0.0 })
            .collect();
        (q, rows, n_eq)
    }

    #[test]
    fn agrees_with_clarabel_on_banded_lps() {
        for (seed, eq) in [(1, false), (2, false), (3, true), (4, true), (5, false)] {
            let (q, rows, n_eq) = banded_lp(200, seed, eq);
            let ours = solve(&q, &rows, n_eq, 1e-12, 1e-13, None)
                .unwrap_or_else(|e| panic!("seed {seed}: {e:?}"));
            let theirs = clarabel(&q, &rows, n_eq);
            let (t0, t1) = (dot(&q, &ours.x), dot(&q, &theirs));
            assert!(
                (t0 - t1).abs() <= 1e-7 * t1.abs(),
                "seed {seed}: objective {t0} against Clarabel's {t1}"
            );
            // Feasible to the tolerance.
            for r in 0..rows.len() {
                let a: f64 = rows
                    .triplets(r)
                    .map(|t| rows.v[t] * ours.x[rows.j[t]])
                    .sum();
                let viol = if r < n_eq {
                    (a - rows.h[r]).abs()
                } else {
                    a - rows.h[r]
                };
                assert!(viol <= 1e-7, "seed {seed}: row {r} violated by {viol}");
            }
            assert!(ours.iterations < 40, "{} iterations", ours.iterations);
        }
    }

    /// A warm start reaches the cold start's optimum, and in fewer iterations over these LPs
    /// together: the same LP with rows added that its solution violates (the active set's
    /// re-solve), and the same rows with another objective (the next SCP iterate's, roughly).
    #[test]
    fn a_warm_start_reaches_the_same_optimum_sooner() {
        let (mut warm_total, mut cold_total) = (0, 0);
        for (seed, eq) in [(11, false), (12, true), (13, false), (14, true)] {
            let (q, rows, n_eq) = banded_lp(200, seed, eq);
            let first = solve(&q, &rows, n_eq, 1e-10, 1e-11, None).expect("solves");
            // Rows x_j ≤ 0.97 x_j* on every tenth column: all violated by the solution.
            let mut more = Rows::default();
            more.append(&rows);
            for j in (0..q.len()).step_by(10) {
                more.push(&[(j, 1.0)], 0.97 * first.x[j]);
            }
            // Another objective: every weight moved by up to 30 %.
            let mut st = seed;
            let q2: Vec<f64> = q.iter().map(|v| v * (1.0 + 0.3 * rnd(&mut st))).collect();
            for (q, rows) in [(&q, &more), (&q2, &rows)] {
                let mut duals = first.duals.clone();
                duals.resize(rows.len(), f64::NAN);
                let start = WarmStart {
                    x: &first.x,
                    duals: &duals,
                };
                // Without `solve`'s cold retry: the warm start itself must converge.
                let warm = solve_from(q, rows, n_eq, 1e-10, 1e-11, Some(&start))
                    .unwrap_or_else(|e| panic!("seed {seed}: warm start {e:?}"));
                let cold = solve_from(q, rows, n_eq, 1e-10, 1e-11, None).expect("cold");
                let (tw, tc) = (dot(q, &warm.x), dot(q, &cold.x));
                assert!(
                    (tw - tc).abs() <= 1e-8 * tc.abs(),
                    "seed {seed}: warm {tw} against cold {tc}"
                );
                warm_total += warm.iterations;
                cold_total += cold.iterations;
            }
        }
        assert!(
            warm_total < cold_total,
            "{warm_total} iterations warm, {cold_total} cold"
        );
    }

    #[test]
    fn an_infeasible_lp_is_not_answered() {
        let mut rows = Rows::default();
        rows.push(&[(0, 1.0)], 1.0);
        rows.push(&[(0, -1.0)], -2.0);
        assert!(solve(&[-1.0], &rows, 0, 1e-8, 1e-8, None).is_err());
    }

    #[test]
    fn a_wide_problem_is_left_to_clarabel() {
        let mut rows = Rows::default();
        let c: Vec<(usize, f64)> = (0..40).map(|j| (j, 1.0)).collect();
        rows.push(&c, 1.0);
        assert_eq!(
            solve(&[-1.0; 40], &rows, 0, 1e-8, 1e-8, None).err(),
            Some(Unsolved::NotBanded(39))
        );
    }
}
