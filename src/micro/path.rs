//! The motion before a warm-started solve's first Newton step, and the yarn crossings along it (docs/sampling.md:
//! a defined Ψ̄ needs every start to stay in its fabric).
//!
//! A chain hands a solve the equilibrium of a neighbouring strain. Before Newton starts, that state moves twice:
//!
//! 1. to the new strain at fixed local displacements ũ and angles θ ([`MicroProblem::move_to`]): the vertices
//!    ride with the surface map, x_v = φ(X̄_v) + n x̄_v,z + R_v ũ_v, while ũ stays; two yarns whose contact holds
//!    them a large ũ apart can pass through each other when the macro strain changes by a grid step;
//! 2. for a predicted start, from the moved unknowns to the predicted ones at the new strain (a straight line in y).
//!
//! The Newton path's own check ([`super::options::CrossingGuard`]) sees neither. [`MicroProblem::start_crossings`]
//! follows both motions: the first in the steps [`MicroProblem::move_to`] takes (each a straight line of every
//! copy's world position between two strains, [`crate::contact::ccd::crossings_between`]), the second as one
//! straight line. A switch between the bending families at zero curvature is a rigid rotation and crosses
//! nothing.

use super::elimination::Elimination;
use super::solver::{move_strain, MicroError, MicroProblem, MicroState};
use super::strain::MacroStrain;
use crate::contact::ccd::Crossing;

impl MicroProblem {
    /// The yarn crossings while `origin` (an equilibrium) moves to the start of a solve at `target`: at fixed ũ
    /// and θ to `start`'s strain, then linearly in the unknowns to `start` (nothing when `start` is `origin`: a
    /// plain warm start), then at fixed ũ and θ to `target` (module documentation).
    pub fn start_crossings(
        &self,
        origin: &MicroState,
        start: &MicroState,
        target: &MacroStrain,
    ) -> Result<Vec<Crossing>, MicroError> {
        target.validate_for_radius(self.pattern.radius)?;
        let mut out = Vec::new();
        let mut state = origin.clone();
        self.moving_crossings(&mut state, &start.strain, &mut out)?;
        if state.family != start.family {
            self.switch_family(&mut state, start.family);
        }
        if state.y != start.y {
            let elim = Elimination::in_family(&self.pattern, &start.strain, start.family);
            out.extend(self.tile(&elim).crossings(&state.y, &start.y)?);
        }
        let mut state = start.clone();
        self.moving_crossings(&mut state, target, &mut out)?;
        Ok(out)
    }

    /// The crossings of `state` moving at fixed ũ and θ to `target` in [`MicroProblem::move_to`]'s steps (leaving
    /// its family at zero curvature if `target` needs the other one); `state` ends at `target` (its frames are not
    /// transported: only the centre lines matter here).
    fn moving_crossings(
        &self,
        state: &mut MicroState,
        target: &MacroStrain,
        out: &mut Vec<Crossing>,
    ) -> Result<(), MicroError> {
        let family = target.validate_for_radius(self.pattern.radius)?;
        if family != state.family {
            let mut flat = state.strain;
            flat.0[3] = 0.0;
            flat.0[4] = 0.0;
            self.moving_crossings_within(state, &flat, out)?;
            self.switch_family(state, family);
        }
        self.moving_crossings_within(state, target, out)
    }

    fn moving_crossings_within(
        &self,
        state: &mut MicroState,
        target: &MacroStrain,
        out: &mut Vec<Crossing>,
    ) -> Result<(), MicroError> {
        let from = state.strain;
        if from == *target {
            return Ok(());
        }
        let steps = self.move_steps(&from, target);
        let mut old = self.tile(&Elimination::in_family(&self.pattern, &from, state.family));
        for s in 1..=steps {
            let z = move_strain(&from, target, s, steps);
            let new = self.tile(&Elimination::in_family(&self.pattern, &z, state.family));
            out.extend(old.crossings_to(&state.y, &new, &state.y)?);
            old = new;
            state.strain = z;
        }
        Ok(())
    }
}
