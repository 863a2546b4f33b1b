//! Predictors for continuation along a chain of strains (docs/micro-solver.md): the start state of a solve at a
//! strain next to one or two equilibria already found.
//!
//! - Secant ([`MicroProblem::predict`]): from two equilibria, y extrapolated linearly along the chain; it returns
//!   the state at the target strain with the frames transported to the predicted unknowns.
//! - None: the previous equilibrium itself, moved to the new strain at fixed unknowns.
//!
//! A tangent predictor y* + (dy*/dz)·Δz was measured and not adopted (more steps, other branches; see
//! `docs/notes/retired-micro-solver-rules.md`).

use super::elimination::Elimination;
use super::solver::{local, MicroProblem, MicroState};
use super::strain::{MacroStrain, StrainError};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Which predictor a chain of solves uses after its first step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Predictor {
    /// Linear extrapolation from the two previous equilibria ([`MicroProblem::predict`]).
    #[default]
    Secant,
    /// The previous equilibrium itself (moved to the new strain at fixed unknowns).
    None,
}

impl MicroProblem {
    /// A secant predictor for continuation along a chain of strains: from the equilibria `prev` at z₀ and `cur`
    /// at z₁ (same family), the state at `target` with y extrapolated linearly, y₁ + (y₁ − y₀)·t, where t is the
    /// projection of target − z₁ on z₁ − z₀ relative to |z₁ − z₀|² (strain components weighted 1, curvatures by
    /// the larger period). Returns `None` when the families differ or the step is degenerate; the frames are
    /// transported to the predicted state.
    pub fn predict(
        &self,
        prev: &MicroState,
        cur: &MicroState,
        target: &MacroStrain,
    ) -> Result<Option<MicroState>, StrainError> {
        let family = target.validate()?;
        if prev.family != cur.family || cur.family != family {
            return Ok(None);
        }
        let pmax = self.pattern.periods[0].max(self.pattern.periods[1]);
        let w = |k: usize| if k < 3 { 1.0 } else { pmax };
        let d1: Vec<f64> = (0..5)
            .map(|k| (cur.strain.0[k] - prev.strain.0[k]) * w(k))
            .collect();
        let d2: Vec<f64> = (0..5)
            .map(|k| (target.0[k] - cur.strain.0[k]) * w(k))
            .collect();
        let n1: f64 = d1.iter().map(|v| v * v).sum();
        if n1 <= 0.0 {
            return Ok(None);
        }
        let t = d1.iter().zip(&d2).map(|(a, b)| a * b).sum::<f64>() / n1;
        if !(t > 0.0 && t <= 2.0) {
            return Ok(None);
        }
        let mut state = cur.clone();
        self.move_to(&mut state, target)?;
        let y: Vec<f64> = cur
            .y
            .iter()
            .zip(&prev.y)
            .map(|(a, b)| a + t * (a - b))
            .collect();
        self.place(&mut state, y);
        Ok(Some(state))
    }

    /// Set the unknowns of a state already at its strain, transporting its frames to them.
    fn place(&self, state: &mut MicroState, y: Vec<f64>) {
        let n = self.pattern.len();
        let elim = Elimination::in_family(&self.pattern, &state.strain, state.family);
        let positions: Vec<Vector3<f64>> = (0..n)
            .map(|v| elim.position(v, [0, 0], &local(&y, v)))
            .collect();
        let theta = y[3 * n..].to_vec();
        state.frames.advance(
            &self.pattern,
            &self.topology,
            positions,
            theta,
            &elim.transforms,
        );
        state.y = y;
    }
}
