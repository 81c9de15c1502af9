//! stats — the order statistics the data, fit and diagnose stages share
//! (one median, one quantile, not one per module).
//!
//! Must never: panic on empty or non-finite input, or allocate when given a
//! slice to work in.

/// Median of the finite values of `v`: the upper median (element n/2 in
/// sorted order: the exact median for odd n, a value the data hold for even
/// n); None when no value is finite.
///
/// ```ignore
/// assert_eq!(crate::stats::median([3.0, f64::NAN, 1.0, 2.0]), Some(2.0));
/// ```
pub(crate) fn median(v: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
    let m = median_in_place(&mut v);
    (!v.is_empty()).then_some(m)
}

/// Upper median of `v`, reordering it in place (no allocation); NaN when
/// empty. Non-finite values count as values (NaN after +∞): filter first.
pub(crate) fn median_in_place(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f64::total_cmp).1
}

/// The `q`-quantile of `v` (0 ≤ q ≤ 1, clamped): the element of rank
/// round((n − 1)·q) in sorted order (nearest rank, a value the data hold),
/// reordering `v` in place (no allocation); NaN when empty. Non-finite
/// values count as values, as in [`median_in_place`].
pub(crate) fn quantile_in_place(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = ((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    *v.select_nth_unstable_by(k, f64::total_cmp).1
}

/// Levels of `items` by `key`, lowest first: a level is anchored on its
/// first (lowest) member, and an item joins the last level while
/// `same(anchor, key)` holds, so a slow drift cannot chain distinct set
/// points into one level. Items whose key is not finite are left out; the
/// order within a level is by key, ties as given.
///
/// ```ignore
/// let l = crate::stats::anchored_levels([222.0, 1556.0, 226.0, 1561.0], |x| *x, |a, b| b - a < 60.0);
/// assert_eq!(l, [vec![222.0, 226.0], vec![1556.0, 1561.0]]);
/// ```
pub(crate) fn anchored_levels<T>(
    items: impl IntoIterator<Item = T>,
    key: impl Fn(&T) -> f64,
    same: impl Fn(f64, f64) -> bool,
) -> Vec<Vec<T>> {
    let mut v: Vec<(f64, T)> = items
        .into_iter()
        .map(|x| (key(&x), x))
        .filter(|(k, _)| k.is_finite())
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut levels: Vec<(f64, Vec<T>)> = Vec::new();
    for (k, x) in v {
        match levels.last_mut() {
            Some((anchor, m)) if same(*anchor, k) => m.push(x),
            _ => levels.push((k, vec![x])),
        }
    }
    levels.into_iter().map(|(_, m)| m).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upper_median_of_the_finite_values() {
        assert_eq!(median([3.0, f64::NAN, 1.0, 2.0]), Some(2.0));
        assert_eq!(median([4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median([f64::NAN, f64::INFINITY]), None);
        assert_eq!(median(Vec::new()), None);
        let mut v = [5.0, -1.0, 2.0];
        assert_eq!(median_in_place(&mut v), 2.0);
        assert!(median_in_place(&mut []).is_nan());
    }

    #[test]
    fn nearest_rank_quantiles() {
        let mut v: Vec<f64> = (1..=101).rev().map(f64::from).collect();
        assert_eq!(quantile_in_place(&mut v, 0.0), 1.0);
        assert_eq!(quantile_in_place(&mut v, 0.01), 2.0);
        assert_eq!(quantile_in_place(&mut v, 0.5), 51.0);
        assert_eq!(quantile_in_place(&mut v, 0.99), 100.0);
        assert_eq!(quantile_in_place(&mut v, 1.5), 101.0);
        assert!(quantile_in_place(&mut [], 0.5).is_nan());
    }

    /// Levels anchor on their lowest member: values 5 apart with a
    /// tolerance of 8 make levels of two, not one chain; NaN is left out.
    #[test]
    fn levels_are_anchored_on_their_lowest_member() {
        let within8 = |a: f64, b: f64| b - a <= 8.0;
        let l = anchored_levels([15.0, 0.0, f64::NAN, 10.0, 5.0, 20.0], |x| *x, within8);
        assert_eq!(l, [vec![0.0, 5.0], vec![10.0, 15.0], vec![20.0]]);
        // Items other than the key, ties in the order given.
        let l = anchored_levels([(1, 3.0), (2, 100.0), (3, 3.0)], |p| p.1, within8);
        assert_eq!(l, [vec![(1, 3.0), (3, 3.0)], vec![(2, 100.0)]]);
        assert!(anchored_levels(Vec::<f64>::new(), |x| *x, within8).is_empty());
    }
}
