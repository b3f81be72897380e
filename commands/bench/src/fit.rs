//! Curves of error against cost on log–log axes: the fitted convergence slope,
//! and the time a strategy needs to reach a given error.

/// The least-squares slope of `ln y` against `ln x` over the points with both
/// coordinates positive and finite; `None` with fewer than two distinct `x`.
///
/// An unbiased Monte Carlo estimator's mean squared error falls as `N⁻¹` (slope
/// −1 for MSE, −½ for RMSE); stratified and quasi-Monte Carlo estimators reach up
/// to `N⁻³ᐟ²` for MSE on 2D integrands with discontinuities (Owen 1997; pbrt-v4
/// §8.2.2), steeper for smooth ones.
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    (logs.len() >= 2 && sxx > 1e-12).then(|| sxy / sxx)
}

/// Where a curve of `(cost, error)` points reaches `target` error: linear
/// interpolation of `ln cost` against `ln error` between the two points that
/// bracket the target, taken in order of cost. Outside the points' range the
/// line through the two nearest points is extended, and `extrapolated` is set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub cost: f64,
    pub extrapolated: bool,
}

/// See [`Crossing`]. `None` when fewer than two usable points remain or the
/// curve is flat where the target would be reached.
pub fn cost_to_reach(points: &[(f64, f64)], target: f64) -> Option<Crossing> {
    let mut logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(c, e)| *c > 0.0 && *e > 0.0 && c.is_finite() && e.is_finite())
        .map(|(c, e)| (c.ln(), e.ln()))
        .collect();
    if logs.len() < 2 || target.is_nan() || target <= 0.0 {
        return None;
    }
    logs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let t = target.ln();
    let bracket = logs
        .windows(2)
        .position(|w| (w[0].1 - t) * (w[1].1 - t) <= 0.0 && w[0].1 != w[1].1);
    let (segment, extrapolated) = match bracket {
        Some(i) => (i, false),
        // Not reached within the points: extend the end the target lies beyond.
        None => {
            let last = logs.len() - 2;
            let falling = logs[last + 1].1 < logs[0].1;
            let beyond_low_end = if falling {
                t > logs[0].1
            } else {
                t < logs[0].1
            };
            (if beyond_low_end { 0 } else { last }, true)
        }
    };
    let (a, b) = (logs[segment], logs[segment + 1]);
    if a.1 == b.1 {
        return None;
    }
    let cost = a.0 + (t - a.1) * (b.0 - a.0) / (b.1 - a.1);
    Some(Crossing {
        cost: cost.exp(),
        extrapolated,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_an_exact_power_law() {
        let pts: Vec<(f64, f64)> = [1.0, 4.0, 16.0, 64.0]
            .iter()
            .map(|&n: &f64| (n, 3.0 * n.powf(-1.5)))
            .collect();
        assert!((log_log_slope(&pts).unwrap() + 1.5).abs() < 1e-12);
        assert_eq!(log_log_slope(&pts[..1]), None);
        assert_eq!(log_log_slope(&[(2.0, 1.0), (2.0, 0.5)]), None);
        // Non-positive errors (an identical image) are left out, not fitted as −∞.
        let with_zero = [(1.0, 1.0), (4.0, 0.25), (16.0, 0.0)];
        assert!((log_log_slope(&with_zero).unwrap() + 1.0).abs() < 1e-12);
    }

    #[test]
    fn crossing_interpolates_and_extrapolates_on_log_log_axes() {
        // error = 1/cost.
        let pts = [(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)];
        let inside = cost_to_reach(&pts, 0.05).unwrap();
        assert!((inside.cost - 20.0).abs() < 1e-9 && !inside.extrapolated);
        let beyond = cost_to_reach(&pts, 0.001).unwrap();
        assert!((beyond.cost - 1000.0).abs() < 1e-6 && beyond.extrapolated);
        let before = cost_to_reach(&pts, 10.0).unwrap();
        assert!((before.cost - 0.1).abs() < 1e-9 && before.extrapolated);
        // Unordered input is sorted by cost first.
        let shuffled = [(100.0, 0.01), (1.0, 1.0), (10.0, 0.1)];
        assert_eq!(cost_to_reach(&shuffled, 0.05), Some(inside));
        assert_eq!(cost_to_reach(&pts[..1], 0.5), None);
        assert_eq!(cost_to_reach(&[(1.0, 0.5), (2.0, 0.5)], 0.1), None);
    }
}
