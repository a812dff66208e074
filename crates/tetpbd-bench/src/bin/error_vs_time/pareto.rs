//! Pareto fronts of (ms per frame, error) points and the headline comparisons between them.

/// A point: cost and error, with the index of the row it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Median ms per frame.
    pub ms: f64,
    /// Error (any metric, lower is better).
    pub err: f64,
    /// Row index.
    pub row: usize,
}

/// The points no other point beats in both cost and error, cheapest first. Non-finite points
/// are left out.
pub fn front(points: &[Point]) -> Vec<Point> {
    let mut p: Vec<Point> = points
        .iter()
        .copied()
        .filter(|p| p.ms.is_finite() && p.err.is_finite())
        .collect();
    p.sort_by(|a, b| a.ms.total_cmp(&b.ms).then(a.err.total_cmp(&b.err)));
    let mut out: Vec<Point> = Vec::new();
    for q in p {
        if out.last().is_none_or(|l| q.err < l.err) {
            out.push(q);
        }
    }
    out
}

/// One comparison at a point of the other engine's front.
#[derive(Clone, Copy, Debug)]
pub struct Match {
    /// The other engine's point.
    pub theirs: Point,
    /// Our cheapest point with an error at most theirs (equal error).
    pub at_equal_error: Option<Point>,
    /// Our most accurate point costing at most theirs (equal time).
    pub at_equal_time: Option<Point>,
}

impl Match {
    /// How many times faster we are at equal error.
    pub fn speedup(&self) -> Option<f64> {
        self.at_equal_error.map(|o| self.theirs.ms / o.ms)
    }

    /// How many times smaller our error is at equal time (1 when both are exactly 0).
    pub fn accuracy_gain(&self) -> Option<f64> {
        self.at_equal_time.map(|o| match (self.theirs.err, o.err) {
            (t, e) if t == 0.0 && e == 0.0 => 1.0,
            (t, e) => t / e.max(f64::MIN_POSITIVE),
        })
    }
}

/// Compares our front with theirs at each of their front points.
pub fn compare(ours: &[Point], theirs: &[Point]) -> Vec<Match> {
    let ours = front(ours);
    front(theirs)
        .into_iter()
        .map(|t| Match {
            theirs: t,
            at_equal_error: ours
                .iter()
                .filter(|o| o.err <= t.err)
                .min_by(|a, b| a.ms.total_cmp(&b.ms))
                .copied(),
            at_equal_time: ours
                .iter()
                .filter(|o| o.ms <= t.ms)
                .min_by(|a, b| a.err.total_cmp(&b.err))
                .copied(),
        })
        .collect()
}

/// Median of the finite values, or None.
pub fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(ms: f64, err: f64, row: usize) -> Point {
        Point { ms, err, row }
    }

    #[test]
    fn front_keeps_only_undominated_points() {
        let f = front(&[
            p(1.0, 1.0, 0),
            p(2.0, 2.0, 1),
            p(3.0, 0.5, 2),
            p(0.5, f64::NAN, 3),
        ]);
        assert_eq!(f.iter().map(|q| q.row).collect::<Vec<_>>(), vec![0, 2]);
    }

    #[test]
    fn compare_finds_equal_error_and_equal_time_points() {
        let ours = [p(1.0, 0.1, 0), p(4.0, 0.01, 1)];
        let m = compare(&ours, &[p(2.0, 0.05, 2), p(8.0, 0.02, 3)]);
        assert_eq!(m.len(), 2);
        // Equal error 0.05: our cheapest is the 4 ms run; equal time 2 ms: our 1 ms run.
        assert_eq!(m[0].at_equal_error.map(|q| q.row), Some(1));
        assert_eq!(m[0].speedup(), Some(0.5));
        assert!((m[0].accuracy_gain().unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(m[1].speedup(), Some(2.0));
        assert!((m[1].accuracy_gain().unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(median(vec![3.0, 1.0, 2.0, f64::NAN]), Some(2.0));
        let zero = compare(&[p(1.0, 0.0, 0)], &[p(2.0, 0.0, 1)]);
        assert_eq!(zero[0].accuracy_gain(), Some(1.0));
    }
}
