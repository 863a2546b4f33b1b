//! The terms of Φ besides the elastic energy (module documentation of [`super`]): per vertex (inertia, linear
//! drag, gravity, obstacle penalty, friction, handle springs) and per face (stiffness-proportional damping, air
//! drag), with the data they freeze at the start of a substep.

use super::{dissipation, non_finite_material, obstacle, Simulation, Target};
use crate::shell::assemble::{assemble, assemble_keeping, gather, zero_absent_flaps, Assembled};
use crate::shell::dissipation::DragFace;
use crate::shell::element::ElementModel;
use crate::shell::obstacle::FrictionContact;
use crate::shell::strain::NDOF;
use crate::shell::{Psd, ShellError};
use rayon::prelude::*;

/// One contribution of [`Simulation::sparse_terms`].
enum Term {
    /// a value only (its gradient comes as a `Face`)
    Value(f64),
    /// value, vertex, gradient and Hessian block of a per-vertex term
    Vertex(f64, usize, [f64; 3], [[f64; 3]; 3]),
    /// gradient over a stencil and, unless precomputed, its Hessian
    Face(usize, [f64; NDOF], Option<Box<[[f64; NDOF]; NDOF]>>),
}

/// What a substep freezes at xₙ.
pub(super) struct Lagged {
    /// per stencil, the PSD elastic Hessian at xₙ (empty without damping)
    damping: std::sync::Arc<Vec<[[f64; NDOF]; NDOF]>>,
    /// (c/h) Σ of those Hessians in the pattern's order (empty without damping)
    damping_values: Vec<f64>,
    /// per stencil, its face's drag data (empty without wind)
    drag: Vec<Option<DragFace>>,
    /// vertices in an obstacle layer with their frozen normal and normal force, and the obstacle's translation
    /// over the substep (empty without friction)
    friction: Vec<(FrictionContact, [f64; 3])>,
}

impl Simulation {
    /// The lagged data of a substep starting at `xn` and ending at `t1`, for the effective step `h` and the
    /// velocity anchor `anchor` (xₙ itself for implicit Euler; [`super::integrator`]) and the obstacles' anchors
    /// (their placements combined as the anchor combines the cloth's states): geometry from xₙ, velocities
    /// measured from the anchors (damping and drag only in dynamic mode).
    pub(super) fn lagged(
        &self,
        xn: &[f64],
        anchor: &[f64],
        h: f64,
        t1: f64,
        obstacle_anchors: &[[f64; 3]],
    ) -> Result<Lagged, ShellError> {
        let s = &self.settings;
        let dynamic = !s.quasi_static;
        let mut damping = std::sync::Arc::new(Vec::new());
        let mut damping_values = Vec::new();
        let cached = self
            .damping_cache
            .as_ref()
            .filter(|(x, local)| x.as_slice() == xn && local.len() == self.stencils.len());
        if dynamic && s.damping > 0.0 && cached.is_some() {
            // the last converged assembly was at xₙ: its local PSD Hessians are the ones needed
            // (an Arc: shared, not copied)
            damping = cached.map(|c| c.1.clone()).unwrap_or_default();
        } else if dynamic && s.damping > 0.0 {
            // the dissipation must be convex: option (c) (exact Hessian) is replaced by option (b)
            let mut model: ElementModel = self.model.clone();
            if model.psd == Psd::None {
                model.psd = Psd::Psi;
            }
            damping = std::sync::Arc::new(
                self.stencils
                    .par_iter()
                    .map(|st| {
                        let q = gather(st, xn);
                        let mut g = [0.0; NDOF];
                        let mut hm = [[0.0; NDOF]; NDOF];
                        model.energy_gradient_hessian(&q, &st.rest, st.flaps, &mut g, &mut hm)?;
                        zero_absent_flaps(&mut hm, st, model.bending);
                        Some(hm)
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        let step = self.steps + 1;
                        non_finite_material(&self.model, &self.stencils, xn, Some(step))
                            .unwrap_or(ShellError::Degenerate { step })
                    })?,
            );
        }
        if !damping.is_empty() {
            damping_values = vec![0.0; self.pattern.nnz()];
            let coh = s.damping / h;
            for (si, (st, hm)) in self.stencils.iter().zip(damping.iter()).enumerate() {
                let scaled = hm.map(|row| row.map(|x| coh * x));
                self.pattern
                    .add_stencil_hessian(&mut damping_values, si, st, &scaled);
            }
        }
        let drag = if dynamic && !s.wind.is_off() {
            self.stencils
                .iter()
                .map(|st| {
                    let p = |a: usize| std::array::from_fn(|k| xn[3 * st.v[a] + k]);
                    let b = |a: usize| std::array::from_fn(|k| anchor[3 * st.v[a] + k]);
                    let mut face = dissipation::drag_face([p(0), p(1), p(2)], st.rest.area)?;
                    face.xn = [b(0), b(1), b(2)];
                    Some(face)
                })
                .collect()
        } else {
            vec![]
        };
        let mut friction = Vec::new();
        if s.friction > 0.0 {
            for v in 0..self.pattern.n {
                if self.pattern.free[v].is_none() {
                    continue;
                }
                let p = [xn[3 * v], xn[3 * v + 1], xn[3 * v + 2]];
                for (i, motion) in self.obstacle_motions.iter().enumerate() {
                    let pr = self.obstacle_proximity(i, p, self.time);
                    let pen = s.thickness - pr.d;
                    if pen > 0.0 {
                        let (o0, o1) = (obstacle_anchors[i], motion.position(t1));
                        friction.push((
                            FrictionContact {
                                vertex: v,
                                n: pr.n,
                                lambda: self.mass[v] * s.contact_stiffness * pen * pen,
                            },
                            std::array::from_fn(|c| o1[c] - o0[c]),
                        ));
                    }
                }
            }
        }
        Ok(Lagged {
            damping,
            damping_values,
            drag,
            friction,
        })
    }

    /// The per-vertex terms of one free vertex v at position p: value, gradient, Hessian block.
    fn vertex_terms(&self, v: usize, x: &[f64], tg: &Target) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        let s = &self.settings;
        let h = tg.h;
        let m = self.mass[v];
        let p = [x[3 * v], x[3 * v + 1], x[3 * v + 2]];
        let (mut e, mut g, mut blk) = self.obstacle_terms(v, p, tg.time);
        for c in 0..3 {
            let i = 3 * v + c;
            let dn = x[i] - tg.xn[i];
            e -= m * s.gravity[c] * dn;
            g[c] -= m * s.gravity[c];
            if !s.quasi_static {
                let dt = x[i] - tg.xt[i];
                e += 0.5 * m * dt * dt / (h * h) + 0.5 * s.drag * m * dn * dn / h;
                g[c] += m * dt / (h * h) + s.drag * m * dn / h;
                blk[c][c] += m / (h * h) + s.drag * m / h;
            }
        }
        (e, g, blk)
    }

    /// The non-elastic part of Φ at x.
    pub(super) fn external_value(&self, x: &[f64], tg: &Target) -> f64 {
        let per_vertex: f64 = (0..self.pattern.n)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&v| self.pattern.free[v].is_some())
            .map(|v| self.vertex_terms(v, x, tg).0)
            .sum();
        let mut e = per_vertex;
        self.sparse_terms(x, tg, |t| match t {
            Term::Value(v) | Term::Vertex(v, ..) => e += v,
            Term::Face(..) => {}
        });
        e
    }

    /// The terms that touch few vertices or whole faces: friction, springs, air drag and damping, handed to
    /// `emit` one by one (damping's Hessian is precomputed in [`Lagged`]).
    fn sparse_terms(&self, x: &[f64], tg: &Target, mut emit: impl FnMut(Term)) {
        let s = &self.settings;
        let eps = s.friction_velocity * tg.h;
        for (fc, moved) in &tg.lagged.friction {
            let v = fc.vertex;
            let delta = std::array::from_fn(|c| x[3 * v + c] - tg.xn[3 * v + c] - moved[c]);
            let (e, g, hb) = obstacle::friction(fc, s.friction, eps, delta);
            emit(Term::Vertex(e, v, g, hb));
        }
        if let Some(k) = s.handle_stiffness {
            for &(v, p) in &tg.springs {
                let d: [f64; 3] = std::array::from_fn(|c| x[3 * v + c] - p[c]);
                let e = 0.5 * k * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                let hb = std::array::from_fn(|a| std::array::from_fn(|b| k * f64::from(a == b)));
                emit(Term::Vertex(e, v, d.map(|t| k * t), hb));
            }
        }
        for (si, df) in tg.lagged.drag.iter().enumerate() {
            let Some(df) = df else { continue };
            let st = &self.stencils[si];
            let q: [f64; 9] = std::array::from_fn(|i| x[3 * st.v[i / 3] + i % 3]);
            let (e, g9, h9) = dissipation::drag(df, &s.wind, tg.h, &q);
            emit(Term::Value(e));
            let mut g = [0.0; NDOF];
            g[..9].copy_from_slice(&g9);
            let mut hm = Box::new([[0.0; NDOF]; NDOF]);
            for r in 0..9 {
                hm[r][..9].copy_from_slice(&h9[r]);
            }
            emit(Term::Face(si, g, Some(hm)));
        }
        let coh = s.damping / tg.h;
        for (si, hm) in tg.lagged.damping.iter().enumerate() {
            let st = &self.stencils[si];
            let q = gather(st, x);
            let qn = gather(st, &tg.xn);
            let dq: [f64; NDOF] = std::array::from_fn(|i| q[i] - qn[i]);
            let (e, g) = dissipation::damping(hm, coh, &dq);
            emit(Term::Value(e));
            emit(Term::Face(si, g, None));
        }
    }

    /// Assembled elastic terms plus the others: (assembly with the full Hessian values, full gradient of Φ
    /// including constrained vertices — with their inertia — for the reaction forces).
    pub(super) fn gradient_hessian(
        &self,
        x: &[f64],
        tg: &Target,
    ) -> Result<(Assembled, Vec<f64>), ShellError> {
        let s = &self.settings;
        // keep the local Hessians for the next substep's damping when they are the ones it needs
        let keep = !s.quasi_static && s.damping > 0.0 && self.model.psd != Psd::None;
        let asm = if keep {
            assemble_keeping(
                &self.model,
                &self.stencils,
                &self.pattern,
                x,
                self.exact_first(),
            )
        } else {
            assemble(
                &self.model,
                &self.stencils,
                &self.pattern,
                x,
                true,
                self.exact_first(),
            )
        };
        let mut asm = asm.ok_or_else(|| {
            let step = self.steps + 1;
            non_finite_material(&self.model, &self.stencils, x, Some(step))
                .unwrap_or(ShellError::Degenerate { step })
        })?;
        let mut g = std::mem::take(&mut asm.grad);
        let exact = !asm.values_exact.is_empty();
        for v in 0..self.pattern.n {
            let (_, gv, blk) = self.vertex_terms(v, x, tg);
            for c in 0..3 {
                g[3 * v + c] += gv[c];
            }
            if let Some(k) = self.pattern.free[v] {
                self.pattern.add_diag_block(&mut asm.values, k, &blk);
                if exact {
                    self.pattern.add_diag_block(&mut asm.values_exact, k, &blk);
                }
            }
        }
        for (a, b) in asm.values.iter_mut().zip(&tg.lagged.damping_values) {
            *a += b;
        }
        for (a, b) in asm.values_exact.iter_mut().zip(&tg.lagged.damping_values) {
            *a += b;
        }
        let pattern = &self.pattern;
        let mut values = std::mem::take(&mut asm.values);
        let mut values_exact = std::mem::take(&mut asm.values_exact);
        self.sparse_terms(x, tg, |t| match t {
            Term::Value(_) => {}
            Term::Vertex(_, v, gv, hb) => {
                for c in 0..3 {
                    g[3 * v + c] += gv[c];
                }
                if let Some(k) = pattern.free[v] {
                    pattern.add_diag_block(&mut values, k, &hb);
                    if exact {
                        pattern.add_diag_block(&mut values_exact, k, &hb);
                    }
                }
            }
            Term::Face(si, gs, hm) => {
                let st = &self.stencils[si];
                for a in 0..6 {
                    if a >= 3 && !st.flaps[a - 3] {
                        continue;
                    }
                    for c in 0..3 {
                        g[3 * st.v[a] + c] += gs[3 * a + c];
                    }
                }
                if let Some(hm) = hm {
                    pattern.add_stencil_hessian(&mut values, si, st, &hm);
                    if exact {
                        pattern.add_stencil_hessian(&mut values_exact, si, st, &hm);
                    }
                }
            }
        });
        asm.values = values;
        asm.values_exact = values_exact;
        Ok((asm, g))
    }
}
