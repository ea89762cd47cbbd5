//! The Pareto front of a set of settings: those that no other setting beats on both error and
//! cost (both minimized). A setting is dominated when another has error <= and cost <= with
//! at least one strictly less; settings equal on both are on the front together.
//!
//! [`front`] takes plain `(error, cost)` points, so a sweep, a tune run or any other caller can
//! use it; [`mark_sweep`] marks the rows of a sweep on two fronts: the mean 8-bit error against
//! area (`area_ge`) and against frame cycles (`cycles`, where the timing model ran).

use crate::summary::SweepRow;

/// Whether each point is on the Pareto front of the points (error, cost), both minimized.
/// Points with a non-finite coordinate are never on it and dominate nothing. O(n log n).
#[must_use]
pub fn front(points: &[(f64, f64)]) -> Vec<bool> {
    let mut on = vec![false; points.len()];
    let mut idx: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    idx.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pa.1.total_cmp(&pb.1).then(pa.0.total_cmp(&pb.0))
    });
    // The least error among the points of strictly lower cost than the current group.
    let mut best = f64::INFINITY;
    let mut g = 0;
    while g < idx.len() {
        let cost = points[idx[g]].1;
        let mut end = g;
        while end < idx.len() && points[idx[end]].1 == cost {
            end += 1;
        }
        // Sorted by error within the group: the first has the group's least error.
        let e_min = points[idx[g]].0;
        if e_min < best {
            for &i in &idx[g..end] {
                if points[i].0 == e_min {
                    on[i] = true;
                }
            }
            best = e_min;
        }
        g = end;
    }
    on
}

/// The error of a sweep row on its fronts: the mean absolute 8-bit error against the
/// reference (`error_8bit.mean_abs_lsb`); `None` without a reference.
#[must_use]
pub fn sweep_error(r: &SweepRow) -> Option<f64> {
    r.error_8bit.as_ref().map(|e| e.mean_abs_lsb)
}

/// Sets `pareto_area` (error vs `area_ge`) and `pareto_cycles` (error vs `cycles`; `None`
/// for every row when some row has no cycle count) of every row.
pub fn mark_sweep(rows: &mut [SweepRow]) {
    let err = |r: &SweepRow| sweep_error(r).unwrap_or(f64::NAN);
    let area: Vec<(f64, f64)> = rows.iter().map(|r| (err(r), r.area_ge as f64)).collect();
    let on_area = front(&area);
    let all_cycles = rows.iter().all(|r| r.cycles.is_some());
    let cycles: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (err(r), r.cycles.map_or(f64::NAN, |c| c as f64)))
        .collect();
    let on_cycles = front(&cycles);
    for (i, r) in rows.iter_mut().enumerate() {
        r.pareto_area = sweep_error(r).is_some() && on_area[i];
        r.pareto_cycles = all_cycles.then_some(on_cycles[i]);
    }
}

/// The terminal mark of a row: `area`, `cycles`, `area+cycles` or `-`.
#[must_use]
pub fn mark(r: &SweepRow) -> &'static str {
    match (r.pareto_area, r.pareto_cycles == Some(true)) {
        (true, true) => "area+cycles",
        (true, false) => "area",
        (false, true) => "cycles",
        (false, false) => "-",
    }
}
