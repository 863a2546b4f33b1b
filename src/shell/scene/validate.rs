//! Checks of a scene's values that serde cannot make (ranges and the documented limits).

use super::*;

impl Scene {
    /// Check values serde cannot (sizes, times, physical parameters, against their ranges and the documented
    /// limits [`MAX_STEPS`], [`MAX_GRAVITY`], [`MAX_NEWTON`]); errors name the field.
    pub(super) fn validate(&self, file: &str) -> Result<(), ShellError> {
        self.validate_times(file)?;
        self.validate_solver(file)?;
        self.validate_physics(file)?;
        self.validate_geometry(file)
    }

    /// `duration`, `dt` (not larger than a positive duration), the step count and the handles' keyframe times.
    fn validate_times(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        if !(self.duration >= 0.0 && self.duration.is_finite()) {
            return bad(
                "duration",
                format!("must be a non-negative number, got {}", self.duration),
            );
        }
        if !(self.dt > 0.0 && self.dt.is_finite()) {
            return bad("dt", format!("must be positive, got {}", self.dt));
        }
        if self.dt < MIN_DT {
            return bad(
                "dt",
                format!("{} s is below the limit of {MIN_DT:e} s", self.dt),
            );
        }
        if self.duration > 0.0 && self.dt > self.duration {
            return bad(
                "dt",
                format!(
                    "{} s is larger than the duration {} s (one step would overshoot it)",
                    self.dt, self.duration
                ),
            );
        }
        let steps = (self.duration / self.dt - 1e-9).ceil();
        // finite duration ≥ 0 and dt > 0: a number or +inf, never NaN
        if steps > MAX_STEPS as f64 {
            return bad(
                "dt",
                format!(
                    "duration / dt = {steps:e} steps is more than the limit of {MAX_STEPS} (a larger dt or a \
                     shorter duration?)"
                ),
            );
        }
        let motions = self
            .handles
            .iter()
            .enumerate()
            .map(|(i, h)| (format!("handles[{i}].keyframes"), h.motion()))
            .chain(self.obstacles.iter().enumerate().filter_map(|(i, o)| {
                o.motion()
                    .map(|m| (format!("obstacles[{i}].motion"), m.clone()))
            }));
        for (field, m) in motions {
            if let Err(e) = m.check() {
                return bad(&field, e.to_string());
            }
            if m.keyframes.iter().any(|k| {
                !within(&k.offset, MAX_COORDINATE)
                    || !k.velocity.is_none_or(|v| within(&v, MAX_COORDINATE))
            }) {
                return bad(
                    &field,
                    format!(
                        "translations must be within ±{MAX_COORDINATE:e} m and velocities within \
                         ±{MAX_COORDINATE:e} m/s"
                    ),
                );
            }
        }
        Ok(())
    }

    /// The solver's settings: force tolerance, iteration, halving and substep limits, the time tolerance.
    fn validate_solver(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        if self.solver.force_tol.is_nan() || self.solver.force_tol <= 0.0 {
            return bad(
                "solver.force_tol",
                format!("must be positive, got {}", self.solver.force_tol),
            );
        }
        if self.solver.max_newton > MAX_NEWTON {
            return bad(
                "solver.max_newton",
                format!(
                    "{} is more than the limit of {MAX_NEWTON}",
                    self.solver.max_newton
                ),
            );
        }
        if self.solver.max_halvings > MAX_HALVINGS {
            return bad(
                "solver.max_halvings",
                format!(
                    "{} is more than the limit of {MAX_HALVINGS}",
                    self.solver.max_halvings
                ),
            );
        }
        if !(1..=MAX_SUBSTEPS).contains(&self.solver.substeps) {
            return bad(
                "solver.substeps",
                format!(
                    "must be a whole number from 1 to {MAX_SUBSTEPS}, got {}",
                    self.solver.substeps
                ),
            );
        }
        if let Some(tol) = self.solver.time_tol {
            if !(tol > 0.0 && tol.is_finite()) {
                return bad(
                    "solver.time_tol",
                    format!("must be a positive length (m) or null, got {tol}"),
                );
            }
        }
        Ok(())
    }

    /// Gravity (bounded by [`MAX_GRAVITY`]), drag, the model's scales and the contact parameters.
    fn validate_physics(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        let g = self.gravity;
        let gnorm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        if gnorm.is_nan() || gnorm > MAX_GRAVITY {
            return bad(
                "gravity",
                format!("magnitude {gnorm:e} m/s² is more than the limit of {MAX_GRAVITY:e} m/s²"),
            );
        }
        if !(self.drag >= 0.0 && self.drag.is_finite()) {
            return bad(
                "drag",
                format!("must be a non-negative rate (1/s), got {}", self.drag),
            );
        }
        let m = &self.model;
        for (f, v) in [("model.stiffness", m.stiffness), ("model.mass", m.mass)] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(f, format!("must be positive, got {v}"));
            }
        }
        if !(m.bending_scale >= 0.0 && m.bending_scale.is_finite()) {
            return bad(
                "model.bending_scale",
                format!("must be a non-negative number, got {}", m.bending_scale),
            );
        }
        if let Some(Err((key, msg))) = m.fold_barrier.map(|f| f.check()) {
            return bad(&format!("model.fold_barrier.{key}"), msg);
        }
        if let Some(Err((key, msg))) = m.collapse_barrier.map(|f| f.check()) {
            return bad(&format!("model.collapse_barrier.{key}"), msg);
        }
        let w = &self.wind;
        for (f, v) in [
            ("damping", self.damping),
            ("wind.density", w.density),
            ("wind.drag", w.drag),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(f, format!("must be a non-negative number, got {v}"));
            }
        }
        if !w.velocity.iter().all(|x| x.abs() <= MAX_COORDINATE) {
            return bad(
                "wind.velocity",
                format!("components must be within ±{MAX_COORDINATE:e} m/s"),
            );
        }
        if let Some(k) = self.handle_stiffness {
            if !(k > 0.0 && k.is_finite()) {
                return bad(
                    "handle_stiffness",
                    format!("must be a positive stiffness (N/m) or null, got {k}"),
                );
            }
        }
        let c = &self.contact;
        if !(c.friction_velocity > 0.0 && c.friction_velocity.is_finite()) {
            return bad(
                "contact.friction_velocity",
                format!(
                    "must be a positive velocity (m/s), got {}",
                    c.friction_velocity
                ),
            );
        }
        for (f, v) in [
            ("contact.thickness", c.thickness),
            ("contact.stiffness", c.stiffness),
            ("contact.friction", c.friction),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(f, format!("must be a non-negative number, got {v}"));
            }
        }
        Ok(())
    }

    /// The fabric angle, the placement, the handle offsets and the obstacles (bounded by [`MAX_COORDINATE`] and
    /// [`MAX_AXIS`]).
    fn validate_geometry(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        let pl = &self.placement;
        if !within(&pl.origin, MAX_COORDINATE) {
            return bad(
                "placement.origin",
                format!("coordinates must be within ±{MAX_COORDINATE:e} m"),
            );
        }
        if !(within(&pl.u, MAX_AXIS) && within(&pl.v, MAX_AXIS)) {
            return bad(
                "placement",
                format!("the components of u and v must be within ±{MAX_AXIS:e}"),
            );
        }
        if let MeshSpec::Obj { transform, .. } = &self.mesh {
            if !transform_ok(transform) {
                return bad(
                    "mesh.obj.transform",
                    format!(
                        "needs a positive scale ≤ {MAX_AXIS:e}, a finite rotation and a translation within \
                         ±{MAX_COORDINATE:e} m"
                    ),
                );
            }
        }
        if !self.fabric_angle_deg.is_finite() {
            return bad("fabric_angle_deg", "must be finite".into());
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let ok = match o {
                ObstacleSpec::Mesh { transform, .. } => transform_ok(transform),
                ObstacleSpec::Sphere { center, radius, .. } => {
                    *radius > 0.0 && *radius <= MAX_COORDINATE && within(center, MAX_COORDINATE)
                }
                ObstacleSpec::Plane { point, normal, .. } if within(point, MAX_COORDINATE) => {
                    let l = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2])
                        .sqrt();
                    l > 0.0 && l.is_finite()
                }
                ObstacleSpec::Plane { .. } => false,
            };
            if !ok {
                return bad(
                    &format!("obstacles[{i}]"),
                    format!(
                        "needs a positive radius / non-zero normal / positive scale and finite rotation, \
                         coordinates within ±{MAX_COORDINATE:e} m"
                    ),
                );
            }
        }
        Ok(())
    }
}

/// A usable placement: positive finite scale up to [`MAX_AXIS`], finite rotation, translation within
/// [`MAX_COORDINATE`].
fn transform_ok(t: &Transform) -> bool {
    t.scale > 0.0
        && t.scale <= MAX_AXIS
        && t.rotate.iter().all(|x| x.is_finite())
        && t.translate.iter().all(|x| x.abs() <= MAX_COORDINATE)
}

/// Every component within ±limit (false for NaN).
fn within(v: &[f64], limit: f64) -> bool {
    v.iter().all(|x| x.abs() <= limit)
}
