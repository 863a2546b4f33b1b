//! Checked entry points of the rod stencils (docs/robustness.md): the same value, gradient and Hessian as
//! [`stretch_vgh`] and [`bend_twist_vgh`] (`docs/yarn-model.md`, "Discrete elastic rods"), for inputs that do not come
//! from the solver's own state — every input is checked first (finite, within [`MAX_COORDINATE`], edges of
//! positive length), and a result that is not finite (an overflow) is an error instead of NaN or inf.

use super::bend_twist::{bend_twist_vgh, BendTwistParams, StencilFrames};
use super::stretch::stretch_vgh;
use nalgebra::{SMatrix, SVector, Vector3};

/// The largest |coordinate| (m) and |angle| (rad) a checked stencil accepts: the scenes' bound on positions; far
/// beyond any yarn tile, and small enough that squared lengths cannot overflow.
pub const MAX_COORDINATE: f64 = 1e6;

/// Why a checked rod stencil was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RodError {
    /// An input is not finite or beyond its bound.
    #[error("rod stencil: {what} = {value} is not finite or beyond ±{limit:e}")]
    Input {
        /// which input
        what: &'static str,
        /// its value
        value: f64,
        /// its bound
        limit: f64,
    },
    /// An edge of zero length (its tangent is undefined).
    #[error("rod stencil: edge {edge} has zero length")]
    ZeroLength {
        /// the edge (0 or 1)
        edge: usize,
    },
    /// The result overflowed.
    #[error("rod stencil: the {what} is not finite (the inputs are too extreme)")]
    NonFinite {
        /// the quantity that overflowed
        what: &'static str,
    },
}

fn check(what: &'static str, value: f64, limit: f64) -> Result<(), RodError> {
    if value.is_finite() && value.abs() <= limit {
        Ok(())
    } else {
        Err(RodError::Input { what, value, limit })
    }
}

fn check_points(points: &[&Vector3<f64>]) -> Result<(), RodError> {
    for p in points {
        for &c in p.iter() {
            check("a coordinate", c, MAX_COORDINATE)?;
        }
    }
    for (edge, w) in points.windows(2).enumerate() {
        if (w[1] - w[0]).norm_squared() == 0.0 {
            return Err(RodError::ZeroLength { edge });
        }
    }
    Ok(())
}

fn finite_result<const N: usize>(
    value: f64,
    g: &SVector<f64, N>,
    h: &SMatrix<f64, N, N>,
) -> Result<(), RodError> {
    if !value.is_finite() {
        return Err(RodError::NonFinite { what: "energy" });
    }
    if !g.iter().all(|v| v.is_finite()) {
        return Err(RodError::NonFinite { what: "gradient" });
    }
    if !h.iter().all(|v| v.is_finite()) {
        return Err(RodError::NonFinite { what: "Hessian" });
    }
    Ok(())
}

/// [`stretch_vgh`] with its inputs checked (rest length finite and > 0, stiffness finite and ≥ 0) and its result
/// finite.
#[allow(clippy::type_complexity)]
pub fn stretch_checked(
    x0: &Vector3<f64>,
    x1: &Vector3<f64>,
    rest_length: f64,
    ks: f64,
) -> Result<(f64, SVector<f64, 6>, SMatrix<f64, 6, 6>), RodError> {
    check_points(&[x0, x1])?;
    if !(rest_length > 0.0 && rest_length.is_finite()) {
        return Err(RodError::Input {
            what: "the rest length",
            value: rest_length,
            limit: f64::MAX,
        });
    }
    check("the stretching stiffness", ks, f64::MAX)?;
    let (e, g, h) = stretch_vgh(x0, x1, rest_length, ks);
    finite_result(e, &g, &h)?;
    Ok((e, g, h))
}

/// [`bend_twist_vgh`] with its inputs checked (positions, angles, stored frames and parameters finite; the
/// Voronoi length > 0) and its result finite.
#[allow(clippy::type_complexity)]
pub fn bend_twist_checked(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    p: &BendTwistParams,
) -> Result<(f64, SVector<f64, 11>, SMatrix<f64, 11, 11>), RodError> {
    check_points(&[&x[0], &x[1], &x[2]])?;
    for t in theta {
        check("an angle θ", t, MAX_COORDINATE)?;
    }
    for v in [fr.t0, fr.u0, fr.t1, fr.u1] {
        for &c in v.iter() {
            check("a stored frame component", c, MAX_COORDINATE)?;
        }
    }
    check("the stored reference twist", fr.twist, MAX_COORDINATE)?;
    for (what, v) in [
        ("a rest curvature", p.rest_curvature[0]),
        ("a rest curvature", p.rest_curvature[1]),
        ("the rest twist", p.rest_twist),
        ("the bending stiffness", p.bend),
        ("the twisting stiffness", p.twist),
    ] {
        check(what, v, f64::MAX)?;
    }
    if !(p.voronoi_length > 0.0 && p.voronoi_length.is_finite()) {
        return Err(RodError::Input {
            what: "the Voronoi length",
            value: p.voronoi_length,
            limit: f64::MAX,
        });
    }
    let (e, g, h) = bend_twist_vgh(x, theta, fr, p);
    finite_result(e, &g, &h)?;
    Ok((e, g, h))
}
