//! The dexel model of seed 003: lines parallel to Z on a regular XY grid, each holding the
//! sorted, disjoint intervals of material along it.
//!
//! Dexel (i, j) stands for the cell `[x0 + i hx, x0 + (i+1) hx] × [y0 + j hy, y0 + (j+1) hy]`
//! and samples it at its centre; its material counts as `length × hx × hy`. A box stock whose
//! sides lie on the grid is represented exactly; elsewhere the volume's error is of the order
//! of the cell size times the boundary's area. Several intervals per dexel keep undercuts of a
//! tilted tool right (a line may pass through material, a cut, and material again).
//!
//! **Storage** (issue 13: memory and set-up no more than the cut needs). The grid is stored in
//! tiles of [`TILE`] × [`TILE`] dexels, each made from the stock ([`Stock::column`]) the first
//! time a cut reaches it; a tile never cut costs one null pointer, and reading it gives the
//! stock's column. A dexel holds one or two intervals inline (a tilted tool's undercut leaves
//! material below it and above its flutes) and goes to the heap only for three or more; in
//! every form it keeps, in the same four numbers, its lowest and highest material and a range
//! of z holding none ([`Dexel`]), so that a removal that misses is told without asking which
//! form the dexel has.

use super::stock::Stock;

/// Removals shorter than this (mm) are rounding, not cutting: they leave the dexel unchanged.
pub const MIN_CUT_MM: f64 = 1e-9;

/// Dexels along each side of a tile (module doc).
pub const TILE: usize = 16;

const INF: f64 = f64::INFINITY;

/// Cell index `i` as a float: `i as f64`, by way of `i32`, whose conversion is one instruction
/// and vectorises, where `u64`'s is not on x86-64 without AVX-512DQ (a dozen instructions per
/// cell in the rows' loops); the same value for `i` < 2³¹, which [`Dexels::new`] holds.
#[inline(always)]
pub(crate) fn index_f64(i: usize) -> f64 {
    i as i32 as f64
}

/// One dexel's material: sorted, disjoint intervals `[z0, z1]` (40 bytes; the heap only for
/// three or more intervals).
///
/// `iv` is `[[z0, g0], [g1, z1]]` in every form: z0 the lowest material (∞: none), z1 the
/// highest (−∞: none) and [g0, g1] a range of z without material (or g0 > g1):
/// - no interval: `[[∞, −∞], [∞, −∞]]` (the gap [−∞, ∞]);
/// - one, `[a, b]`: `[[a, b], [∞, b]]` (the gap: everything above b);
/// - two, `[a, b]` and `[c, d]`: `[[a, b], [c, d]]` (the gap between them);
/// - three or more (`many`): `[[first a, g0], [g1, last b]]` with [g0, g1] the widest gap
///   between two of them.
///
/// Inline (`many` is `None`), the intervals are `iv`'s first zero, one or two; on the heap,
/// `many`'s.
#[derive(Debug, Clone, PartialEq)]
pub struct Dexel {
    iv: [[f64; 2]; 2],
    /// A thin pointer (a `Vec` or a boxed slice would make a dexel 48 or 56 bytes: a fifth
    /// more memory for the few dexels of three intervals or more).
    #[allow(clippy::box_collection)]
    many: Option<Box<Vec<[f64; 2]>>>,
}

impl Default for Dexel {
    fn default() -> Dexel {
        Dexel::EMPTY
    }
}

impl Dexel {
    /// No material.
    pub const EMPTY: Dexel = Dexel {
        iv: [[INF, -INF], [INF, -INF]],
        many: None,
    };

    /// One interval (the stock's column, or what stays of it after cuts from above or below).
    pub fn one(iv: [f64; 2]) -> Dexel {
        Dexel {
            iv: [iv, [INF, iv[1]]],
            many: None,
        }
    }

    /// Two intervals, in order (a tilted tool's undercut: material below it and above its
    /// flutes).
    pub fn two(a: [f64; 2], b: [f64; 2]) -> Dexel {
        Dexel {
            iv: [a, b],
            many: None,
        }
    }

    /// Three or more sorted, disjoint intervals, on the heap.
    fn many(v: Vec<[f64; 2]>) -> Dexel {
        Dexel {
            iv: summary(&v),
            many: Some(Box::new(v)),
        }
    }

    /// The dexel of a stock column.
    pub fn from_column(column: Option<[f64; 2]>) -> Dexel {
        column.map_or(Dexel::EMPTY, Dexel::one)
    }

    /// The dexel of sorted, disjoint intervals, in its inline form where it has one.
    fn from_intervals(v: Vec<[f64; 2]>) -> Dexel {
        match v.len() {
            0 => Dexel::EMPTY,
            1 => Dexel::one(v[0]),
            2 => Dexel::two(v[0], v[1]),
            _ => Dexel::many(v),
        }
    }

    /// The intervals, sorted and disjoint.
    pub fn intervals(&self) -> &[[f64; 2]] {
        match &self.many {
            Some(v) => v,
            None => {
                let n = if self.iv[1][0] != INF {
                    2
                } else if self.iv[0][0] != INF {
                    1
                } else {
                    0
                };
                &self.iv[..n]
            }
        }
    }

    /// No material.
    pub fn is_empty(&self) -> bool {
        self.iv[0][0] == INF
    }

    /// The highest material (−∞: none).
    #[inline]
    pub fn top(&self) -> f64 {
        self.iv[1][1]
    }

    /// Three or more intervals, held on the heap.
    pub fn on_heap(&self) -> bool {
        self.many.is_some()
    }

    /// The lowest and the highest material, if any.
    pub fn extent(&self) -> Option<[f64; 2]> {
        (!self.is_empty()).then_some([self.iv[0][0], self.iv[1][1]])
    }

    /// The material's total length, mm.
    pub fn length(&self) -> f64 {
        self.intervals().iter().map(|iv| iv[1] - iv[0]).sum()
    }

    /// Whether removing `[lo, hi]` may take material: false where it certainly takes none
    /// (then [`Dexel::remove`] returns [`Cut::NONE`] and leaves the dexel unchanged). All
    /// material lies in [z0, z1] and none in the gap [g0, g1] (`iv`), so where z1 ≤ lo,
    /// z0 ≥ hi or g0 ≤ lo, hi ≤ g1 every overlap max(`iv[0]`, lo) … min(`iv[1]`, hi) is empty
    /// and the removal would return [`Cut::NONE`] unchanged; so it does where lo > hi
    /// (shorter than [`MIN_CUT_MM`]: a miss, [∞, −∞], too). The same four numbers in every
    /// form and the tests joined without short-circuit: no branch but the answer's.
    #[inline]
    pub fn cuts(&self, lo: f64, hi: f64) -> bool {
        let [[z0, g0], [g1, z1]] = self.iv;
        let in_gap = (g0 <= lo) & (hi <= g1);
        (lo <= hi) & (z1 > lo) & (z0 < hi) & !in_gap
    }

    /// Removes `[lo, hi]`; returns what was removed (length 0: nothing). As [`remove`] on
    /// the intervals.
    ///
    /// Inline where `[lo, hi]` misses the material ([`Dexel::cuts`]: most of a cut's
    /// removals, the tool's back passing through what the step before left, or through the
    /// tunnel it cut), the rest out of line.
    #[inline]
    pub fn remove(&mut self, lo: f64, hi: f64) -> Cut {
        if self.cuts(lo, hi) {
            self.remove_any(lo, hi)
        } else {
            Cut::NONE
        }
    }

    /// [`Dexel::remove`] on any dexel.
    #[inline(never)]
    fn remove_any(&mut self, lo: f64, hi: f64) -> Cut {
        if self.many.is_some() {
            return self.remove_many(lo, hi);
        }
        let [f, l] = self.iv;
        if l[0] != INF {
            // Two intervals: `remove`'s steps, without the heap unless a split makes three.
            let v = [f, l];
            if hi - lo < MIN_CUT_MM {
                return Cut::NONE;
            }
            let cut = overlap(&v, lo, hi);
            if cut.length == 0.0 {
                return cut;
            }
            // The commonest cut of a tunnel: [lo, hi] reaches from inside or above the first
            // interval's bottom (a < lo ≤ c) to inside or below the second's top (b ≤ hi < d),
            // widening the gap. Of the four parts below, [a, min(b, lo)] and [max(c, hi), d]
            // stay (both not empty) and the other two are empty ([hi, b]: hi ≥ b; [c, lo]:
            // lo ≤ c): the same two intervals, told without counting them.
            if f[0] < lo && lo <= l[0] && f[1] <= hi && hi < l[1] {
                self.iv = [[f[0], smaller(f[1], lo)], [larger(l[0], hi), l[1]]];
                return cut;
            }
            // What stays of each interval: its parts below lo and above hi (either the
            // whole interval where [lo, hi] misses it, the other empty: f[1] ≤ lo gives
            // [f[0], f[1]] and [hi, f[1]], hi > lo ≥ f[1]), those not empty kept in order
            // (three at most: a split leaves the other interval whole). Built in registers
            // (`put`), not in an array indexed by a count, whose reads the processor cannot
            // take from the writes just before.
            let mut kept = (0, [[0.0; 2]; 3]);
            let mut put = |a: f64, b: f64| {
                if a < b {
                    match kept.0 {
                        0 => kept.1[0] = [a, b],
                        1 => kept.1[1] = [a, b],
                        _ => kept.1[2] = [a, b],
                    }
                    kept.0 += 1;
                }
            };
            put(f[0], smaller(f[1], lo));
            put(larger(f[0], hi), f[1]);
            put(l[0], smaller(l[1], lo));
            put(larger(l[0], hi), l[1]);
            let (n, [x, y, z]) = kept;
            *self = match n {
                0 => Dexel::EMPTY,
                1 => Dexel::one(x),
                2 => Dexel::two(x, y),
                _ => three(x, y, z),
            };
            cut
        } else if f[0] != INF {
            // One interval: `remove`'s steps, the overlap, then what stays.
            let [a0, b0] = f;
            if hi - lo < MIN_CUT_MM || b0 <= lo || a0 >= hi {
                return Cut::NONE;
            }
            let (a, b) = (larger(a0, lo), smaller(b0, hi));
            if b - a < MIN_CUT_MM {
                return Cut::NONE;
            }
            *self = match (a0 < lo, b0 > hi) {
                (false, false) => Dexel::EMPTY,
                (true, false) => Dexel::one([a0, lo]),
                (false, true) => Dexel::one([hi, b0]),
                (true, true) => Dexel::two([a0, lo], [hi, b0]),
            };
            Cut {
                length: b - a,
                z_lo: a,
                z_hi: b,
            }
        } else {
            Cut::NONE
        }
    }

    /// [`Dexel::remove`] on three or more intervals: out of line, so that the heap's work does
    /// not weigh on every call of the inline forms' [`Dexel::remove_any`].
    #[inline(never)]
    fn remove_many(&mut self, lo: f64, hi: f64) -> Cut {
        let Some(v) = self.many.as_deref_mut() else {
            return self.remove_any(lo, hi);
        };
        // The commonest removals from three or more intervals change no interval's count
        // (counted on the LinuxCNC impeller, besides those taking nothing: a bottom trimmed,
        // the top one's top trimmed, the gap between two widened; fewer split one or drop
        // some): told from the first interval they may overlap, f = `v[k]` (k the first
        // with f[1] > lo), and done in place, no interval moved, the summary's widest gap
        // updated in O(1) ([`widened`]) rather than by a pass. What stays is what `remove`
        // keeps (its first and last overlapping intervals are the ones named here, and it
        // keeps [f[0], lo] where f[0] < lo and [hi, l[1]] where l[1] > hi); the cut is the
        // same `overlap` of them, and where it is empty nothing changes, as there.
        if hi - lo < MIN_CUT_MM {
            return Cut::NONE;
        }
        let k = v.partition_point(|iv| iv[1] <= lo);
        let Some(&f) = v.get(k) else {
            // No material above lo.
            return Cut::NONE;
        };
        if f[0] >= hi {
            // [lo, hi] lies in the gap below f (or below all material).
            return Cut::NONE;
        }
        let next = v.get(k + 1).copied();
        if f[0] < lo && f[1] <= hi && next.is_none_or(|l| hi < l[1]) {
            // From inside f to its top or above: f's top trimmed to lo and, where [lo, hi]
            // reaches into the next interval l (l[0] < hi < l[1]; the one after it begins
            // above l[1]), l's bottom to hi.
            let touched = match next {
                Some(l) => [f, l],
                None => [f, [INF, INF]],
            };
            let cut = overlap(&touched, lo, hi);
            if cut.length == 0.0 {
                return cut;
            }
            v[k][1] = lo;
            match next {
                Some(l) => {
                    v[k + 1][0] = larger(l[0], hi);
                    self.iv = widened(self.iv, lo, v[k + 1][0]);
                }
                // The highest material was f's top.
                None => self.iv[1][1] = lo,
            }
            return cut;
        }
        if lo <= f[0] && hi < f[1] {
            // f's bottom trimmed to hi: the gap below it widened, or the lowest material
            // raised.
            let cut = overlap(&[f], lo, hi);
            if cut.length == 0.0 {
                return cut;
            }
            v[k][0] = hi;
            if k == 0 {
                self.iv[0][0] = hi;
            } else {
                self.iv = widened(self.iv, v[k - 1][1], hi);
            }
            return cut;
        }
        let cut = remove(v, lo, hi);
        if cut.length == 0.0 {
            // (`remove` changed nothing.)
            return cut;
        }
        if v.len() <= 2 {
            *self = Dexel::from_intervals(std::mem::take(v));
        } else {
            self.iv = summary(v);
        }
        cut
    }
}

/// `Dexel::iv` of three or more intervals: the lowest and highest material and the widest gap
/// (the first of equal ones).
fn summary(v: &[[f64; 2]]) -> [[f64; 2]; 2] {
    let mut gap = [v[0][1], v[1][0]];
    for w in v[1..].windows(2) {
        if w[1][0] - w[0][1] > gap[1] - gap[0] {
            gap = [w[0][1], w[1][0]];
        }
    }
    [[v[0][0], gap[0]], [gap[1], v[v.len() - 1][1]]]
}

/// A heap dexel's summary (`Dexel::iv`, [`summary`]) after one of its gaps widened to
/// [g0, g1], no other changed: the widest gap, the first of equal ones, is the widened one
/// where it is now wider than the widest [w0, w1], or as wide and not after it (g0 ≤ w0: a gap
/// before it, or it, whose lower end can only have gone down); else it stays.
fn widened(iv: [[f64; 2]; 2], g0: f64, g1: f64) -> [[f64; 2]; 2] {
    let [[z0, w0], [w1, z1]] = iv;
    let (wide, widest) = (g1 - g0, w1 - w0);
    if wide > widest || (wide == widest && g0 <= w0) {
        [[z0, g0], [g1, z1]]
    } else {
        iv
    }
}

/// Three intervals on the heap (a split of one of two), out of line as
/// [`Dexel::remove_many`].
#[inline(never)]
#[cold]
fn three(x: [f64; 2], y: [f64; 2], z: [f64; 2]) -> Dexel {
    Dexel::many(vec![x, y, z])
}

/// The tiles of one row of tiles (its [`TILE`] grid rows), for a cut that changes them; the
/// cut ([`super::cut`]) works on such bands in parallel.
pub(crate) struct Band<'a> {
    grid: &'a Grid,
    /// Tile row index.
    tj: usize,
    tiles: &'a mut [Option<Box<[Dexel]>>],
}

impl Band<'_> {
    /// The grid rows of this band.
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.tj * TILE..((self.tj + 1) * TILE).min(self.grid.ny)
    }

    /// Dexel (i, j), j in [`Band::rows`]; its tile is made from the stock if never cut.
    pub fn dexel(&mut self, i: usize, j: usize) -> &mut Dexel {
        let (ti, tj) = (i / TILE, self.tj);
        let grid = self.grid;
        let tile = self.tiles[ti].get_or_insert_with(|| grid.make_tile(ti, tj));
        &mut tile[(j % TILE) * TILE + i % TILE]
    }

    /// `f(i, dexel)` for dexels `ia..=ib` of row `j` (j in [`Band::rows`]), in order, tile by
    /// tile.
    #[inline(always)]
    pub fn each(&mut self, j: usize, ia: usize, ib: usize, mut f: impl FnMut(usize, &mut Dexel)) {
        let row = (j % TILE) * TILE;
        let mut i = ia;
        while i <= ib {
            let ti = i / TILE;
            let end = ((ti + 1) * TILE - 1).min(ib);
            let (grid, tj) = (self.grid, self.tj);
            let tile = self.tiles[ti].get_or_insert_with(|| grid.make_tile(ti, tj));
            let cells = &mut tile[row + i % TILE..=row + end % TILE];
            for (k, d) in cells.iter_mut().enumerate() {
                f(i + k, d);
            }
            i = end + 1;
        }
    }
}

/// The grid's geometry and the stock untouched tiles stand for.
#[derive(Debug, Clone, Copy)]
struct Grid {
    x0: f64,
    y0: f64,
    hx: f64,
    hy: f64,
    nx: usize,
    ny: usize,
    stock: Stock,
}

impl Grid {
    fn column(&self, i: usize, j: usize) -> Option<[f64; 2]> {
        let (x, y) = (
            self.x0 + (index_f64(i) + 0.5) * self.hx,
            self.y0 + (index_f64(j) + 0.5) * self.hy,
        );
        self.stock.column(x, y)
    }

    /// Tile (ti, tj) as the stock gives it (cells past the grid's edge empty).
    fn make_tile(&self, ti: usize, tj: usize) -> Box<[Dexel]> {
        let mut t = vec![Dexel::EMPTY; TILE * TILE].into_boxed_slice();
        for j in tj * TILE..((tj + 1) * TILE).min(self.ny) {
            for i in ti * TILE..((ti + 1) * TILE).min(self.nx) {
                t[(j % TILE) * TILE + i % TILE] = Dexel::from_column(self.column(i, j));
            }
        }
        t
    }
}

/// A grid of Z-dexels.
#[derive(Debug, Clone)]
pub struct Dexels {
    /// X of the corner of cell (0, 0), mm.
    pub x0: f64,
    /// Y of the corner of cell (0, 0), mm.
    pub y0: f64,
    /// Cell size along X, mm.
    pub hx: f64,
    /// Cell size along Y, mm.
    pub hy: f64,
    /// Cells along X.
    pub nx: usize,
    /// Cells along Y.
    pub ny: usize,
    grid: Grid,
    /// Tiles along X.
    tx: usize,
    /// Row-major (index `tj * tx + ti`): each tile's dexels, row-major, once cut (module doc).
    tiles: Vec<Option<Box<[Dexel]>>>,
    /// Per tile (the same index), the stock's material length over its dexels, mm: what an
    /// untouched tile holds ([`Dexels::volume`]).
    stock_lengths: Vec<f64>,
}

/// What one removal took from one dexel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Cut {
    /// Total length removed, mm.
    pub length: f64,
    /// Lowest z of the material removed, mm.
    pub z_lo: f64,
    /// Highest z of the material removed, mm.
    pub z_hi: f64,
}

impl Cut {
    /// Nothing removed.
    pub const NONE: Cut = Cut {
        length: 0.0,
        z_lo: f64::INFINITY,
        z_hi: f64::NEG_INFINITY,
    };
}

impl Dexels {
    /// The dexels of `stock` on cells of about `cell` mm: the stock's XY bounding rectangle
    /// divided into whole cells (so a box's sides fall on cell edges). The caller has bounded
    /// the cell count. No tile is made yet (module doc).
    pub fn new(stock: &Stock, cell: f64) -> Dexels {
        let [x0, y0, x1, y1] = stock.xy_bounds();
        let nx = ((x1 - x0) / cell).round().max(1.0) as usize;
        let ny = ((y1 - y0) / cell).round().max(1.0) as usize;
        assert!(
            nx < 1 << 31 && ny < 1 << 31,
            "{nx} x {ny} dexels: at most 2^31 - 1 along a side (index_f64)"
        );
        let (hx, hy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        let (tx, ty) = (nx.div_ceil(TILE), ny.div_ceil(TILE));
        // Each row's run of cells with material, counted into its tiles ([`Stock::row_cells`]:
        // a bisection per row rather than a test per cell; 4 M cells on the bundled blade's
        // blank).
        let mut stock_lengths = vec![0.0; tx * ty];
        for j in 0..ny {
            let y = y0 + (index_f64(j) + 0.5) * hy;
            if let Some((ia, ib, length)) = stock.row_cells(y, x0, hx, nx) {
                for ti in ia / TILE..=ib / TILE {
                    let (a, b) = (ia.max(ti * TILE), ib.min((ti + 1) * TILE - 1));
                    stock_lengths[(j / TILE) * tx + ti] += (b - a + 1) as f64 * length;
                }
            }
        }
        Dexels {
            x0,
            y0,
            hx,
            hy,
            nx,
            ny,
            grid: Grid {
                x0,
                y0,
                hx,
                hy,
                nx,
                ny,
                stock: *stock,
            },
            tx,
            tiles: vec![None; tx * ty],
            stock_lengths,
        }
    }

    /// The cell count along X and Y that [`Dexels::new`] makes.
    pub fn shape(stock: &Stock, cell: f64) -> (f64, f64) {
        let [x0, y0, x1, y1] = stock.xy_bounds();
        (
            ((x1 - x0) / cell).round().max(1.0),
            ((y1 - y0) / cell).round().max(1.0),
        )
    }

    /// Centre of column `i` (x), mm.
    pub fn x(&self, i: usize) -> f64 {
        self.x0 + (index_f64(i) + 0.5) * self.hx
    }

    /// Centre of row `j` (y), mm.
    pub fn y(&self, j: usize) -> f64 {
        self.y0 + (index_f64(j) + 0.5) * self.hy
    }

    /// Dexel (i, j) (i < nx, j < ny): its tile's, or the stock's column where no cut has
    /// reached the tile.
    pub fn dexel(&self, i: usize, j: usize) -> Dexel {
        match &self.tiles[(j / TILE) * self.tx + i / TILE] {
            Some(t) => t[(j % TILE) * TILE + i % TILE].clone(),
            None => Dexel::from_column(self.grid.column(i, j)),
        }
    }

    /// Tiles made so far (the rest are the stock's).
    pub fn tiles_made(&self) -> usize {
        self.tiles.iter().filter(|t| t.is_some()).count()
    }

    /// `f(dexel)` for every dexel, row by row (the stock's where no tile is made).
    fn each_row_major(&self, mut f: impl FnMut(&Dexel)) {
        for j in 0..self.ny {
            for ti in 0..self.tx {
                let is = ti * TILE..((ti + 1) * TILE).min(self.nx);
                match &self.tiles[(j / TILE) * self.tx + ti] {
                    Some(t) => {
                        let row = (j % TILE) * TILE;
                        is.for_each(|i| f(&t[row + i % TILE]));
                    }
                    None => is.for_each(|i| f(&Dexel::from_column(self.grid.column(i, j)))),
                }
            }
        }
    }

    /// The material volume, mm³: summed tile by tile (an untouched tile's is the stock's,
    /// counted when the grid was made), the rows of tiles in parallel and added in order (the
    /// same sum on any number of threads).
    pub fn volume(&self) -> f64 {
        use rayon::prelude::*;
        let rows: Vec<f64> = self
            .tiles
            .par_chunks(self.tx)
            .zip(self.stock_lengths.par_chunks(self.tx))
            .map(|(tiles, stock)| {
                tiles
                    .iter()
                    .zip(stock)
                    .map(|(tile, &s)| match tile {
                        Some(t) => t.iter().map(Dexel::length).sum::<f64>(),
                        None => s,
                    })
                    .sum::<f64>()
            })
            .collect();
        rows.iter().sum::<f64>() * self.hx * self.hy
    }

    /// The highest material on each dexel (`NaN` where there is none), row-major: a height map.
    pub fn heights(&self) -> Vec<f64> {
        let mut h = Vec::with_capacity(self.nx * self.ny);
        self.each_row_major(|d| h.push(d.extent().map_or(f64::NAN, |e| e[1])));
        h
    }

    /// The bands of tile rows holding grid rows `j0..=j1`, to change in parallel.
    pub(crate) fn bands(&mut self, j0: usize, j1: usize) -> Vec<Band<'_>> {
        let (tj0, tj1) = (j0 / TILE, j1 / TILE);
        let grid = &self.grid;
        self.tiles[tj0 * self.tx..(tj1 + 1) * self.tx]
            .chunks_mut(self.tx)
            .enumerate()
            .map(|(k, tiles)| Band {
                grid,
                tj: tj0 + k,
                tiles,
            })
            .collect()
    }
}

/// The smaller of two numbers, neither NaN (interval ends and crossings never are): the
/// value `f64::min` gives, by one comparison, without the instructions its handling of NaN
/// costs on every removal.
#[inline]
pub(crate) fn smaller(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// The larger of two numbers, neither NaN, as [`smaller`].
#[inline]
pub(crate) fn larger(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// What removing `[lo, hi]` would take from `intervals`: the overlaps of at least
/// [`MIN_CUT_MM`], their total length and z range (length 0: nothing).
fn overlap(intervals: &[[f64; 2]], lo: f64, hi: f64) -> Cut {
    let mut cut = Cut::NONE;
    for iv in intervals {
        let (a, b) = (larger(iv[0], lo), smaller(iv[1], hi));
        if b - a >= MIN_CUT_MM {
            cut.length += b - a;
            cut.z_lo = smaller(cut.z_lo, a);
            cut.z_hi = larger(cut.z_hi, b);
        }
    }
    cut
}

/// Removes `[lo, hi]` from one dexel's intervals; returns what was removed (length 0: nothing).
pub fn remove(intervals: &mut Vec<[f64; 2]>, lo: f64, hi: f64) -> Cut {
    if hi - lo < MIN_CUT_MM || intervals.is_empty() {
        return Cut::NONE;
    }
    // Only the intervals overlapping [lo, hi] change.
    let first = intervals.partition_point(|iv| iv[1] <= lo);
    let last = intervals.partition_point(|iv| iv[0] < hi);
    if first >= last {
        return Cut::NONE;
    }
    let cut = overlap(&intervals[first..last], lo, hi);
    if cut.length == 0.0 {
        return cut;
    }
    // What stays of the first and last overlapping intervals replaces them in place (the
    // common cases, a trimmed top or a split, move nothing or one element).
    let (f, l) = (intervals[first], intervals[last - 1]);
    let mut keep = [[0.0; 2]; 2];
    let mut n = 0;
    if f[0] < lo {
        keep[n] = [f[0], lo];
        n += 1;
    }
    if l[1] > hi {
        keep[n] = [hi, l[1]];
        n += 1;
    }
    let old = last - first;
    if n <= old {
        intervals[first..first + n].copy_from_slice(&keep[..n]);
        intervals.drain(first + n..last);
    } else {
        // One interval split in two.
        intervals[first] = keep[0];
        intervals.insert(first + 1, keep[1]);
    }
    cut
}

#[cfg(test)]
impl Dexels {
    /// The stock's column at every dexel as a plain row-major grid of interval lists: the
    /// reference the tiled storage and the cut are tested against.
    pub(crate) fn dense_reference(&self, stock: &Stock) -> Vec<Vec<[f64; 2]>> {
        (0..self.ny)
            .flat_map(|j| (0..self.nx).map(move |i| (i, j)))
            .map(|(i, j)| stock.column(self.x(i), self.y(j)).into_iter().collect())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removal_splits_and_trims() {
        let mut d = vec![[0.0, 10.0]];
        let c = remove(&mut d, 3.0, 5.0);
        assert_eq!(d, vec![[0.0, 3.0], [5.0, 10.0]]);
        assert_eq!((c.length, c.z_lo, c.z_hi), (2.0, 3.0, 5.0));
        let c = remove(&mut d, 2.0, 6.0);
        assert_eq!(d, vec![[0.0, 2.0], [6.0, 10.0]]);
        assert!((c.length - 2.0).abs() < 1e-12);
        let c = remove(&mut d, 3.0, 5.0);
        assert_eq!(c.length, 0.0);
        let c = remove(&mut d, -1.0, 20.0);
        assert!(d.is_empty() && (c.length - 6.0).abs() < 1e-12);
    }

    use crate::test_rng as rng;

    #[test]
    fn untouched_tiles_read_as_the_stock() {
        let s = Stock::Cylinder {
            center: [1.0, -2.0],
            radius: 3.3,
            z: [-1.0, 4.0],
        };
        let mut d = Dexels::new(&s, 0.1);
        assert_eq!(d.tiles_made(), 0);
        let column = |d: &Dexels, i, j| Dexel::from_column(s.column(d.x(i), d.y(j)));
        // Cut one dexel: its tile is made, and every dexel still reads as the stock but it.
        let (ci, cj) = (d.nx / 2 + 3, TILE + 5);
        let cut = d.bands(cj, cj)[0].dexel(ci, cj).remove(0.0, 10.0);
        assert_eq!((cut.length, cut.z_lo, cut.z_hi), (4.0, 0.0, 4.0));
        assert_eq!(d.tiles_made(), 1);
        for j in 0..d.ny {
            for i in 0..d.nx {
                let want = if (i, j) == (ci, cj) {
                    Dexel::one([-1.0, 0.0])
                } else {
                    column(&d, i, j)
                };
                assert_eq!(d.dexel(i, j), want, "({i}, {j})");
            }
        }
        let h = d.heights();
        assert_eq!(h.len(), d.nx * d.ny);
        assert_eq!(h[cj * d.nx + ci], 0.0);
        assert!(h[0].is_nan() && h[(d.ny / 2) * d.nx + d.nx / 2] == 4.0);
    }

    /// Random removals on the tiled model and on a plain grid of interval lists (the
    /// representation before tiles) give the same cuts, dexels and volume.
    #[test]
    fn tiles_agree_with_a_dense_grid() {
        let mut rnd = rng(5);
        for case in 0..20 {
            let s = if case % 2 == 0 {
                Stock::Box {
                    min: [0.0, 0.0, -5.0],
                    max: [3.0 + 4.0 * rnd(), 2.0 + 3.0 * rnd(), 0.0],
                }
            } else {
                Stock::Cylinder {
                    center: [0.0, 0.0],
                    radius: 1.0 + 3.0 * rnd(),
                    z: [-5.0, 0.0],
                }
            };
            let cell = 0.05 + 0.1 * rnd();
            let mut d = Dexels::new(&s, cell);
            let mut dense = d.dense_reference(&s);
            // Many removals on the dexels of a window across tile edges: splits and merges.
            let at = |u: f64, n: usize| (TILE - 4 + (24.0 * u) as usize).min(n - 1);
            for _ in 0..2000 {
                let (i, j) = (at(rnd(), d.nx), at(rnd(), d.ny));
                let lo = -6.0 + 7.0 * rnd();
                let hi = lo + 3.0 * rnd() * rnd();
                let want = remove(&mut dense[j * d.nx + i], lo, hi);
                let got = d.bands(j, j)[0].dexel(i, j).remove(lo, hi);
                assert_eq!(got, want);
            }
            for j in 0..d.ny {
                for i in 0..d.nx {
                    assert_eq!(d.dexel(i, j).intervals(), &dense[j * d.nx + i][..]);
                }
            }
            let len: f64 = dense
                .iter()
                .map(|c| c.iter().map(|iv| iv[1] - iv[0]).sum::<f64>())
                .sum();
            // (Summed in another order: tile by tile.)
            let want = len * d.hx * d.hy;
            assert!(
                (d.volume() - want).abs() <= 1e-12 * want,
                "{} {want}",
                d.volume()
            );
        }
    }

    #[test]
    fn a_dexel_is_five_words() {
        assert_eq!(std::mem::size_of::<Dexel>(), 40);
    }

    /// Dexel::remove, through its inline forms (One, Two) and the heap (Many), removes what
    /// the plain interval-list `remove` does, and says the same cut, on random removals
    /// (splits, trims, removals in a gap, shorter than MIN_CUT_MM, touching an end).
    #[test]
    fn the_inline_forms_remove_as_the_interval_list() {
        let mut r = rng(5);
        let mut forms = [0usize; 4];
        for _ in 0..200 {
            let mut d = Dexel::one([0.0, 10.0]);
            let mut list = vec![[0.0, 10.0]];
            for _ in 0..12 {
                let a = 12.0 * r() - 1.0;
                let len = match (r() * 12.0) as usize {
                    0..=2 => 0.5e-9,
                    3..=5 => 0.5 * r(),
                    6..=10 => 4.0 * r(),
                    _ => 15.0, // most or all of what is left
                };
                // Now and then exactly at an interval's end.
                let lo = if r() < 0.2 && !list.is_empty() {
                    list[(r() * list.len() as f64) as usize][1]
                } else {
                    a
                };
                let (got, want) = (d.remove(lo, lo + len), remove(&mut list, lo, lo + len));
                assert_eq!(d.intervals(), &list[..], "remove [{lo}, {}]", lo + len);
                assert_eq!(
                    (got.length, got.z_lo, got.z_hi),
                    (want.length, want.z_lo, want.z_hi)
                );
                let form = match (d.on_heap(), list.len()) {
                    (false, n @ 0..=2) => n,
                    (true, 3..) => 3,
                    (_, n) => panic!("{n} intervals held as {d:?}"),
                };
                // The four numbers every form keeps: the lowest and highest material and a
                // range without any.
                let [[z0, g0], [g1, z1]] = d.iv;
                if d.on_heap() {
                    // The widest gap, the first of equal ones, however it was found.
                    assert_eq!(d.iv, summary(&list), "{d:?}");
                }
                match (list.first(), list.last()) {
                    (Some(f), Some(l)) => assert_eq!((z0, z1), (f[0], l[1]), "{d:?}"),
                    _ => assert!(z0 == f64::INFINITY && z1 == f64::NEG_INFINITY, "{d:?}"),
                }
                assert!(
                    list.iter().all(|iv| iv[1] <= g0 || iv[0] >= g1),
                    "material in the gap of {d:?}"
                );
                forms[form] += 1;
            }
        }
        assert!(
            forms.iter().all(|&n| n > 20),
            "every form exercised: {forms:?}"
        );
    }

    /// The removals a heap dexel does in place ([`Dexel::remove_many`]: a bottom trimmed,
    /// the top one's top trimmed, the gap between two widened, nothing taken) and those it
    /// leaves to `remove` (a split, an interval dropped) leave what `remove` leaves, say the
    /// same cut and keep `summary`'s widest gap, the first of equal ones: from inside an
    /// interval, its bottom or the gap below it to inside it, its top, the gap above, the
    /// next one or beyond, now and then exactly at an end, shorter than [`MIN_CUT_MM`], or
    /// making two gaps equally wide.
    #[test]
    fn a_heap_dexel_in_place_is_the_interval_lists() {
        let mut r = rng(7);
        for _ in 0..400 {
            let mut list: Vec<[f64; 2]> = (0..8)
                .map(|k| [2.0 * k as f64, 2.0 * k as f64 + 1.5])
                .collect();
            let mut d = Dexel::many(list.clone());
            for _ in 0..10 {
                if list.len() < 3 {
                    break;
                }
                let k = (r() * list.len() as f64) as usize;
                let f = list[k];
                let below = if k > 0 { list[k - 1][1] } else { f[0] - 1.0 };
                let lo = match (r() * 6.0) as usize {
                    0 => f[0] + (f[1] - f[0]) * r(),
                    1 => f[0] + 0.5e-9,
                    2 => f[0],
                    3 => below + (f[0] - below) * r(),
                    _ => f[1] - (f[1] - f[0]) * 0.25 * r(),
                };
                let (l, above) = match list.get(k + 1) {
                    Some(&l) => (l, l[0]),
                    None => ([f[1] + 1.0, f[1] + 2.0], f[1] + 1.0),
                };
                let hi = match (r() * 9.0) as usize {
                    0 => f[1],
                    1 => above,
                    2 => l[0] + (l[1] - l[0]) * r(),
                    3 => lo + 0.5e-9,
                    4 => lo + (f[1] - lo) * r(),
                    5 => l[1] + r(),
                    // As wide a gap as the widest so far (a tie), where that reaches.
                    6 => {
                        let widest = list
                            .windows(2)
                            .map(|w| w[1][0] - w[0][1])
                            .fold(0.0, f64::max);
                        (lo + widest).min(l[1] - 1e-3)
                    }
                    _ => f[1] + (above - f[1]) * r(),
                };
                let (got, want) = (d.remove(lo, hi), remove(&mut list, lo, hi));
                assert_eq!(d.intervals(), &list[..], "remove [{lo}, {hi}]");
                assert_eq!(
                    (got.length, got.z_lo, got.z_hi),
                    (want.length, want.z_lo, want.z_hi)
                );
                if d.on_heap() {
                    assert_eq!(d.iv, summary(&list), "{d:?}");
                }
            }
        }
    }

    #[test]
    fn box_volume_is_exact() {
        let s = Stock::Box {
            min: [0.0, 0.0, -5.0],
            max: [30.3, 20.0, 0.0],
        };
        let d = Dexels::new(&s, 0.5);
        assert!((d.volume() - s.volume()).abs() < 1e-9 * s.volume());
    }
}
