//! The Pareto front (`texsim::pareto::front`) against the definition, checked pair by pair on
//! seeded random point sets with many ties, and on a hand-made set.

use crate::rng_common::Rng;
use texsim::pareto::front;

/// The definition, O(n^2): not dominated by any point (<= on both, < on one).
fn brute(p: &[(f64, f64)]) -> Vec<bool> {
    let finite = |a: (f64, f64)| a.0.is_finite() && a.1.is_finite();
    p.iter()
        .map(|&a| {
            finite(a)
                && !p
                    .iter()
                    .any(|&b| finite(b) && b.0 <= a.0 && b.1 <= a.1 && (b.0 < a.0 || b.1 < a.1))
        })
        .collect()
}

#[test]
fn front_matches_the_definition_on_random_sets() {
    let mut rng = Rng(14);
    for case in 0..3000 {
        let n = 1 + rng.below(40) as usize;
        let span = 1 + rng.below(12);
        let p: Vec<(f64, f64)> = (0..n)
            .map(|_| {
                let e = if rng.below(20) == 0 {
                    f64::NAN
                } else {
                    rng.below(span) as f64
                };
                (e, rng.below(span) as f64 * 100.0)
            })
            .collect();
        assert_eq!(front(&p), brute(&p), "case {case}: {p:?}");
    }
}

#[test]
fn front_of_a_hand_made_set() {
    // (error, cost): the cheapest, the most accurate, one between, one dominated, a tie.
    let p = [
        (5.0, 10.0),
        (0.5, 90.0),
        (2.0, 40.0),
        (3.0, 50.0),
        (2.0, 40.0),
        (f64::NAN, 1.0),
    ];
    assert_eq!(front(&p), vec![true, true, true, false, true, false]);
    assert!(front(&[]).is_empty());
}
