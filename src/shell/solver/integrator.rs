//! The time integrators of the cloth solver, as the constants of one substep's incremental potential.
//!
//! Every scheme here minimises Φ(x) = ½‖x − x̂‖²_M / ĥ² + E(x) − f_ext·x + (dissipation in the velocity
//! v = (x − x_b)/ĥ), so a scheme is its effective step ĥ, its inertial target x̂ and its velocity anchor x_b:
//!
//! - **Implicit Euler** (and the original's linearised variant): ĥ = h, x_b = xₙ, x̂ = xₙ + h vₙ.
//! - **BDF2** with variable steps (ω = h / hₙ₋₁, the ratio to the previous substep): the method
//!   α₀ yₙ₊₁ + α₁ yₙ + α₂ yₙ₋₁ = h ẏₙ₊₁ with α₀ = (1 + 2ω)/(1 + ω), α₁ = −(1 + ω), α₂ = ω²/(1 + ω), applied to
//!   ẋ = v and M v̇ = F(x). Eliminating vₙ₊₁ = (α₀ xₙ₊₁ + α₁ xₙ + α₂ xₙ₋₁)/h gives M (xₙ₊₁ − x̂)/ĥ² = F(xₙ₊₁) with
//!   ĥ = h/α₀, x_b = −(α₁ xₙ + α₂ xₙ₋₁)/α₀ and x̂ = x_b − h (α₁ vₙ + α₂ vₙ₋₁)/α₀²; equal steps give the familiar
//!   ĥ = 2h/3, x_b = (4xₙ − xₙ₋₁)/3, x̂ = x_b + (2h/3)(4vₙ − vₙ₋₁)/3. The velocity-dependent forces
//!   (stiffness-proportional damping, drag, friction) are charged at vₙ₊₁ = (x − x_b)/ĥ. Second order and
//!   L-stable (zero-stable for ω < 1 + √2; the step controller grows h by at most 2). The first substep, and
//!   any substep without a previous one, is an implicit Euler substep.
//!
//! **Local error estimates** (m, the largest over the free vertices): implicit Euler's is ½ |x − x̂| (it differs
//! from the trapezoidal rule by h (vₙ₊₁ − vₙ)/2 = ½ (xₙ₊₁ − x̂)). BDF2's compares with the explicit second-order
//! predictor x_p = xₙ + h vₙ + ½ h² (vₙ − vₙ₋₁)/hₙ₋₁ (Milne's device): for x‴ constant and equal steps BDF2 errs
//! by (2/9) h³ x‴ and x_p by −(5/12) h³ x‴, so the error is (2/9)/(2/9 + 5/12) = 8/23 of |x − x_p| (the same
//! constant is used for unequal steps).

/// How a substep advances (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Integrator {
    /// implicit Euler: Φ minimised by Newton's method to the force tolerance (first order)
    #[default]
    ImplicitEuler,
    /// variable-step BDF2: Φ with BDF2's constants minimised to the force tolerance (second order)
    Bdf2,
    /// the original simulator's linearised implicit Euler: one Newton step from xₙ with the PSD Hessian, no
    /// line search (first order)
    Linearized,
}

/// The state at the start of the previous accepted substep, which BDF2 needs.
#[derive(Clone, Debug)]
pub(super) struct History {
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    /// that substep's length (s)
    pub h: f64,
    /// the time it started at (s)
    pub t: f64,
}

/// BDF2's (α₀, α₁, α₂) for the step ratio ω = h / hₙ₋₁.
pub fn bdf2_coefficients(w: f64) -> (f64, f64, f64) {
    ((1.0 + 2.0 * w) / (1.0 + w), -(1.0 + w), w * w / (1.0 + w))
}

/// The constants of one substep's potential (module documentation).
pub(super) struct Anchor {
    /// the effective step ĥ (s)
    pub h: f64,
    /// the velocity anchor x_b
    pub xb: Vec<f64>,
    /// the inertial target x̂
    pub xt: Vec<f64>,
    /// BDF2's predictor x_p (its error estimate), `None` for the first-order schemes
    pub xp: Option<Vec<f64>>,
    /// the weights (w_n, w_{n−1}) that give x_b from (xₙ, xₙ₋₁): (1, 0) for implicit Euler
    pub weights: (f64, f64),
}

impl Anchor {
    /// The constants of a substep of length h from (x, v) with the previous substep `history` (used by BDF2
    /// only); quasi-static substeps have x̂ = x.
    pub fn new(
        integrator: Integrator,
        quasi_static: bool,
        x: &[f64],
        v: &[f64],
        history: Option<&History>,
        h: f64,
    ) -> Anchor {
        match (integrator, history) {
            (Integrator::Bdf2, Some(p)) if !quasi_static => {
                let (a0, a1, a2) = bdf2_coefficients(h / p.h);
                let (wn, wp) = (-a1 / a0, -a2 / a0);
                let xb: Vec<f64> = (0..x.len()).map(|i| wn * x[i] + wp * p.x[i]).collect();
                let xt = (0..x.len())
                    .map(|i| xb[i] - h * (a1 * v[i] + a2 * p.v[i]) / (a0 * a0))
                    .collect();
                let xp = (0..x.len())
                    .map(|i| x[i] + h * v[i] + 0.5 * h * h * (v[i] - p.v[i]) / p.h)
                    .collect();
                Anchor {
                    h: h / a0,
                    xb,
                    xt,
                    xp: Some(xp),
                    weights: (wn, wp),
                }
            }
            _ => Anchor {
                h,
                xb: x.to_vec(),
                xt: if quasi_static {
                    x.to_vec()
                } else {
                    (0..x.len()).map(|i| x[i] + h * v[i]).collect()
                },
                xp: None,
                weights: (1.0, 0.0),
            },
        }
    }

    /// The order of the scheme this substep uses (1 or 2).
    pub fn order(&self) -> i32 {
        if self.xp.is_some() {
            2
        } else {
            1
        }
    }
}

/// The estimated local error of a substep that ended at `x` (module documentation), over the vertices for which
/// `free` holds.
pub(super) fn local_error(
    x: &[f64],
    anchor_xt: &[f64],
    xp: Option<&[f64]>,
    free: impl Fn(usize) -> bool,
) -> f64 {
    let (reference, scale) = match xp {
        Some(xp) => (xp, 8.0 / 23.0),
        None => (anchor_xt, 0.5),
    };
    (0..x.len() / 3)
        .filter(|&v| free(v))
        .map(|v| {
            let d2: f64 = (0..3)
                .map(|c| (x[3 * v + c] - reference[3 * v + c]).powi(2))
                .sum();
            scale * d2.sqrt()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal steps: α = (3/2, −2, 1/2); x_b = (4xₙ − xₙ₋₁)/3, ĥ = 2h/3, x̂ = x_b + (2h/3)(4vₙ − vₙ₋₁)/3.
    #[test]
    fn equal_steps_give_the_textbook_bdf2() {
        assert_eq!(bdf2_coefficients(1.0), (1.5, -2.0, 0.5));
        let p = History {
            x: vec![1.0],
            v: vec![3.0],
            h: 0.1,
            t: 0.0,
        };
        let a = Anchor::new(Integrator::Bdf2, false, &[2.0], &[5.0], Some(&p), 0.1);
        assert!((a.h - 0.2 / 3.0).abs() < 1e-15);
        assert!((a.xb[0] - (8.0 - 1.0) / 3.0).abs() < 1e-15);
        let want = 7.0 / 3.0 + (0.2 / 3.0) * (20.0 - 3.0) / 3.0;
        assert!((a.xt[0] - want).abs() < 1e-14, "{} vs {want}", a.xt[0]);
        assert_eq!(a.order(), 2);
        // without a previous substep it is implicit Euler
        let e = Anchor::new(Integrator::Bdf2, false, &[2.0], &[5.0], None, 0.1);
        assert_eq!((e.h, e.xb[0], e.xt[0], e.order()), (0.1, 2.0, 2.5, 1));
    }

    /// BDF2 integrates x″ = a(t) exactly for quadratic motion with any step ratio: the minimiser of Φ without
    /// elastic forces is x̂ + ĥ² a, which must equal x(t₁) and give v(t₁); the predictor is exact too, so the
    /// error estimate vanishes.
    #[test]
    fn quadratic_motion_is_exact_for_any_step_ratio() {
        let (x, v) = (|t: f64| 0.3 + 0.7 * t - 2.0 * t * t, |t: f64| 0.7 - 4.0 * t);
        for (hp, h) in [(0.1, 0.1), (0.1, 0.2), (0.2, 0.05), (0.03, 0.07)] {
            let (tp, tn) = (0.5, 0.5 + hp);
            let p = History {
                x: vec![x(tp), 0.0, 0.0],
                v: vec![v(tp), 0.0, 0.0],
                h: hp,
                t: tp,
            };
            let a = Anchor::new(
                Integrator::Bdf2,
                false,
                &[x(tn), 0.0, 0.0],
                &[v(tn), 0.0, 0.0],
                Some(&p),
                h,
            );
            let x1 = a.xt[0] + a.h * a.h * (-4.0);
            assert!(
                (x1 - x(tn + h)).abs() < 1e-13,
                "{hp} {h}: {x1} vs {}",
                x(tn + h)
            );
            let v1 = (x1 - a.xb[0]) / a.h;
            assert!((v1 - v(tn + h)).abs() < 1e-12, "{hp} {h}: {v1}");
            let est = local_error(&[x1, 0.0, 0.0], &a.xt, a.xp.as_deref(), |_| true);
            assert!(est < 1e-13, "{hp} {h}: {est}");
        }
    }

    /// For x = t³/6 and equal steps, BDF2's local error is (2/9) h³ and the estimate recovers it.
    #[test]
    fn the_bdf2_estimate_is_calibrated_on_a_cubic() {
        let h = 0.01;
        let (x, v, acc) = (|t: f64| t * t * t / 6.0, |t: f64| t * t / 2.0, |t: f64| t);
        let p = History {
            x: vec![x(-h), 0.0, 0.0],
            v: vec![v(-h), 0.0, 0.0],
            h,
            t: -h,
        };
        let a = Anchor::new(
            Integrator::Bdf2,
            false,
            &[x(0.0), 0.0, 0.0],
            &[v(0.0), 0.0, 0.0],
            Some(&p),
            h,
        );
        let x1 = a.xt[0] + a.h * a.h * acc(h);
        let err = x1 - x(h);
        assert!((err - 2.0 / 9.0 * h * h * h).abs() < 1e-12 * h, "{err}");
        let est = local_error(&[x1, 0.0, 0.0], &a.xt, a.xp.as_deref(), |_| true);
        assert!((est - err.abs()).abs() < 1e-9 * err.abs(), "{est} vs {err}");
    }
}
