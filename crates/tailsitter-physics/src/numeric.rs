//! Numerical helpers shared by the plant, the LQR's model and the analysis.

use std::ops::{Div, IndexMut, Sub};

/// Central-difference Jacobian of `f` at `x`, column by column: for every
/// coordinate `j < n` with a step `h = step(j, x[j])` (`None` skips the column),
/// hands `column(j, (f(x + h·e_j) − f(x − h·e_j)) / 2h)` to the caller, which
/// stores it in a matrix of its own type (static or dynamic).
pub fn central_differences<V, R>(
    x: &V,
    n: usize,
    step: impl Fn(usize, f64) -> Option<f64>,
    mut f: impl FnMut(&V) -> R,
    mut column: impl FnMut(usize, R),
) where
    V: Clone + IndexMut<usize, Output = f64>,
    R: Sub<Output = R> + Div<f64, Output = R>,
{
    for j in 0..n {
        let Some(h) = step(j, x[j]) else {
            continue;
        };
        let mut xp = x.clone();
        let mut xm = x.clone();
        xp[j] += h;
        xm[j] -= h;
        column(j, (f(&xp) - f(&xm)) / (2.0 * h));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn jacobian_of_a_quadratic_map_is_exact() {
        // f(x, y) = (x², x·y): J = [[2x, 0], [y, x]]; central differences are exact
        // for quadratics up to round-off.
        let x = Vector2::new(1.5, -2.0);
        let mut j = Matrix2::zeros();
        central_differences(
            &x,
            2,
            |_, _| Some(1e-3),
            |v: &Vector2<f64>| Vector2::new(v.x * v.x, v.x * v.y),
            |k, col| j.set_column(k, &col),
        );
        let exact = Matrix2::new(3.0, 0.0, -2.0, 1.5);
        assert!((j - exact).amax() < 1e-12, "{j}");
        // A skipped column stays untouched.
        let mut s = Matrix2::from_element(7.0);
        central_differences(
            &x,
            2,
            |k, _| (k == 1).then_some(1e-3),
            |v: &Vector2<f64>| Vector2::new(v.x * v.x, v.x * v.y),
            |k, col| s.set_column(k, &col),
        );
        assert_eq!(s.column(0), Vector2::new(7.0, 7.0).column(0));
        assert!((s[(1, 1)] - 1.5).abs() < 1e-12);
    }
}
