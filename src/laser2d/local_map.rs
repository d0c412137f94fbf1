//! A local point map in the world frame for scan matching: points are binned into square
//! cells and each cell keeps the running mean of the points that fell into it, so that the
//! noise of many scans averages out. The moving-object detector matches every scan against
//! the cell means instead of against the previous scan alone, which keeps the per-scan
//! matching errors from adding up into drift.
//!
//! Not for: occupancy or free-space reasoning, loop closure, or storing moving objects (the
//! caller inserts only points it believes static).

use crate::numerics::floor::floor_i64;
use std::collections::BTreeMap;

/// Cells of running point means; see the module documentation. Iteration order (and so the
/// order of [`LocalMap::means`]) is the cells' index order, independent of insertion order.
#[derive(Clone, Debug)]
pub struct LocalMap {
    cell: f64,
    cells: BTreeMap<(i64, i64), (f64, f64, u32)>,
    means: Vec<[f64; 2]>,
}

impl LocalMap {
    /// An empty map with square cells of side `cell` metres (must be positive).
    pub fn new(cell: f64) -> crate::error::Result<Self> {
        crate::error::ensure_positive("local map cell size", cell)?;
        Ok(LocalMap {
            cell,
            cells: BTreeMap::new(),
            means: Vec::new(),
        })
    }

    /// Number of occupied cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// True when no cell is occupied.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Adds one world-frame point (non-finite points are ignored).
    pub fn insert(&mut self, p: [f64; 2]) {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return;
        }
        let key = (floor_i64(p[0] / self.cell), floor_i64(p[1] / self.cell));
        let e = self.cells.entry(key).or_insert((0.0, 0.0, 0));
        e.0 += p[0];
        e.1 += p[1];
        e.2 = e.2.saturating_add(1);
    }

    /// Removes the cells whose mean lies farther than `radius` from `center`.
    pub fn prune(&mut self, center: [f64; 2], radius: f64) {
        self.cells.retain(|_, &mut (sx, sy, n)| {
            let n = f64::from(n);
            (sx / n - center[0]).hypot(sy / n - center[1]) <= radius
        });
    }

    /// The means of the cells holding at least `min_count` points, in cell order.
    pub fn means(&mut self, min_count: u32) -> &[[f64; 2]] {
        self.means.clear();
        self.means.extend(
            self.cells
                .values()
                .filter(|e| e.2 >= min_count)
                .map(|&(sx, sy, n)| [sx / f64::from(n), sy / f64::from(n)]),
        );
        &self.means
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_average_and_prune() {
        let mut map = LocalMap::new(1.0).unwrap();
        map.insert([0.25, 0.25]);
        map.insert([0.75, 0.75]);
        map.insert([5.5, 0.5]);
        map.insert([f64::NAN, 0.0]);
        assert_eq!(map.len(), 2);
        assert_eq!(map.means(1), &[[0.5, 0.5], [5.5, 0.5]]);
        assert_eq!(map.means(2), &[[0.5, 0.5]]);
        map.prune([0.0, 0.0], 2.0);
        assert_eq!(map.len(), 1);
        assert!(LocalMap::new(0.0).is_err());
    }
}
