//! The dexel model of seed 003: lines parallel to Z on a regular XY grid, each holding the
//! sorted, disjoint intervals of material along it.
//!
//! Dexel (i, j) stands for the cell `[x0 + i hx, x0 + (i+1) hx] × [y0 + j hy, y0 + (j+1) hy]`
//! and samples it at its centre; its material counts as `length × hx × hy`. A box stock whose
//! sides lie on the grid is represented exactly; elsewhere the volume's error is of the order
//! of the cell size times the boundary's area. Several intervals per dexel keep undercuts of a
//! tilted tool right (a line may pass through material, a cut, and material again).

use super::stock::Stock;

/// Removals shorter than this (mm) are rounding, not cutting: they leave the dexel unchanged.
pub const MIN_CUT_MM: f64 = 1e-9;

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
    /// Row-major (index `j * nx + i`): each dexel's material intervals `[z0, z1]`, sorted and
    /// disjoint.
    pub cells: Vec<Vec<[f64; 2]>>,
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

impl Dexels {
    /// The dexels of `stock` on cells of about `cell` mm: the stock's XY bounding rectangle
    /// divided into whole cells (so a box's sides fall on cell edges). The caller has bounded
    /// the cell count.
    pub fn new(stock: &Stock, cell: f64) -> Dexels {
        let [x0, y0, x1, y1] = stock.xy_bounds();
        let nx = ((x1 - x0) / cell).round().max(1.0) as usize;
        let ny = ((y1 - y0) / cell).round().max(1.0) as usize;
        let (hx, hy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        let mut cells = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (x0 + (i as f64 + 0.5) * hx, y0 + (j as f64 + 0.5) * hy);
                cells.push(stock.column(x, y).map_or_else(Vec::new, |c| vec![c]));
            }
        }
        Dexels {
            x0,
            y0,
            hx,
            hy,
            nx,
            ny,
            cells,
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
        self.x0 + (i as f64 + 0.5) * self.hx
    }

    /// Centre of row `j` (y), mm.
    pub fn y(&self, j: usize) -> f64 {
        self.y0 + (j as f64 + 0.5) * self.hy
    }

    /// The material volume, mm³.
    pub fn volume(&self) -> f64 {
        let len: f64 = self
            .cells
            .iter()
            .map(|c| c.iter().map(|iv| iv[1] - iv[0]).sum::<f64>())
            .sum();
        len * self.hx * self.hy
    }

    /// The highest material on each dexel (`NaN` where there is none), row-major: a height map.
    pub fn heights(&self) -> Vec<f64> {
        self.cells
            .iter()
            .map(|c| c.last().map_or(f64::NAN, |iv| iv[1]))
            .collect()
    }
}

/// Removes `[lo, hi]` from one dexel's intervals; returns what was removed (length 0: nothing).
pub fn remove(intervals: &mut Vec<[f64; 2]>, lo: f64, hi: f64) -> Cut {
    let mut cut = Cut {
        length: 0.0,
        z_lo: f64::INFINITY,
        z_hi: f64::NEG_INFINITY,
    };
    if hi - lo < MIN_CUT_MM || intervals.is_empty() {
        return cut;
    }
    // Only the intervals overlapping [lo, hi] change.
    let first = intervals.partition_point(|iv| iv[1] <= lo);
    let last = intervals.partition_point(|iv| iv[0] < hi);
    if first >= last {
        return cut;
    }
    for iv in &intervals[first..last] {
        let (a, b) = (iv[0].max(lo), iv[1].min(hi));
        if b - a >= MIN_CUT_MM {
            cut.length += b - a;
            cut.z_lo = cut.z_lo.min(a);
            cut.z_hi = cut.z_hi.max(b);
        }
    }
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
