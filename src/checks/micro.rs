//! Harness row for the reduced micro energy E(C̃y + d̃) (`docs/derivative-harness.md`, section 1): every unknown of a
//! small generated pattern at once, under an in-plane strain and under bending along each axis. The strain is a
//! fixed parameter of each case (cases cycle through the three), so one row covers all three maps at the cost of
//! one whole-tile row.
//!
//! Reference: the explicit sparse elimination map C̃, d̃ ([`Elimination::matrix`]) applied to the generic unknowns,
//! then the plain sum of the stencils' reference twins; so the row checks the solver's stencil-by-stencil
//! pull-back through the 3×3 rotation blocks against the literal definition. Samples: the state moved to the
//! strain (ũ = 0), and perturbations of 0.05 r / 0.1 rad and 0.2 r / 0.3 rad (θ also shifted by ±2π). Scales
//! as for the whole-tile row ([`crate::tile`]).

use crate::checks::tile::{contact_kink_distance, reference_energy};
use crate::contact::GaussLegendre;
use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::micro::elimination::{stencil_copies, Elimination};
use crate::micro::solver::{MicroProblem, MicroState, SolverOptions};
use crate::micro::strain::MacroStrain;
use crate::pattern::Pattern;
use crate::real::Real;
use crate::rod::YarnMaterial;
use crate::tile::{ContactPair, Terms, Tile, Want};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// The reduced energy of one pattern at one strain as a function of all unknowns y = (ũ, θ).
pub struct StrainCase {
    problem: MicroProblem,
    state: MicroState,
    elim: Elimination,
    contacts: Vec<ContactPair>,
    copies: HashMap<(usize, [i32; 2]), usize>,
    /// C̃ as triplets and d̃.
    c: Vec<(usize, usize, f64)>,
    d: Vec<f64>,
    rule: GaussLegendre,
}

impl StrainCase {
    /// The case of `pattern` with `material` at `strain`: the equilibrium there, its kinematics and contact pairs.
    pub fn new(pattern: Pattern, material: &YarnMaterial, strain: MacroStrain) -> Self {
        let problem = MicroProblem::new(pattern, material, SolverOptions::default());
        let mut state = problem.reference_state();
        problem
            .move_to(&mut state, &strain)
            .expect("the harness strains are admissible");
        let elim = Elimination::in_family(&problem.pattern, &state.strain, state.family);
        let (contacts, list) = {
            let mut tile = problem.tile(&elim);
            let x = tile.home_positions(&state.y);
            tile.update_contacts(&x, problem.options.contact_margin * problem.pattern.radius)
                .expect("the harness pattern has finite positions");
            let list = stencil_copies(&tile);
            (tile.contacts.clone(), list)
        };
        let (c, d) = elim.matrix(&list, problem.pattern.len());
        let copies = list.iter().enumerate().map(|(k, &key)| (key, k)).collect();
        let rule = GaussLegendre::new(problem.material.contact_quadrature);
        StrainCase {
            problem,
            state,
            elim,
            contacts,
            copies,
            c,
            d,
            rule,
        }
    }

    fn tile(&self) -> Tile<'_> {
        let mut t = self.problem.tile(&self.elim);
        t.contacts = self.contacts.clone();
        t
    }
}

impl StrainCase {
    fn dim(&self) -> usize {
        4 * self.problem.pattern.len()
    }
    fn scales(&self) -> Scales {
        let p = &self.problem.pattern;
        let n = p.len() as f64;
        let l = p.edges.iter().map(|e| e.rest_length).sum::<f64>() / n;
        let m = &self.problem.material;
        let k = m.stretch_stiffness() * l
            + (m.bend_stiffness() + m.twist_stiffness()) / l
            + m.contact_stiffness * l * l;
        Scales {
            value: n * k,
            gradient: n.sqrt() * k / l,
            hessian: n.sqrt() * k / (l * l),
        }
    }
    fn input_scale(&self, i: usize) -> f64 {
        if i < 3 * self.problem.pattern.len() {
            self.problem.pattern.radius
        } else {
            1.0
        }
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        if i >= 3 * self.problem.pattern.len() {
            return f64::INFINITY;
        }
        contact_kink_distance(&self.tile(), x, &self.contacts, &self.rule)
    }
    fn reference<D: Real>(&self, y: &[D]) -> D {
        let tile = self.tile();
        let n = self.problem.pattern.len();
        // q = C̃ y + d̃, literally
        let mut q: Vec<D> = self.d.iter().map(|&v| D::from(v)).collect();
        for &(r, c, v) in &self.c {
            q[r] += y[c].clone() * v;
        }
        let k_theta = 3 * self.copies.len();
        let pos = |v: usize, o: [i32; 2]| -> [D; 3] {
            let k = self.copies[&(v, o)];
            [0, 1, 2].map(|c| q[3 * k + c].clone())
        };
        reference_energy(
            &tile,
            &self.state.frames,
            &self.rule,
            &q[k_theta..k_theta + n],
            &pos,
        )
    }
    fn fast(&self, y: &[f64]) -> Vgh {
        let n = self.dim();
        match self
            .tile()
            .evaluate(&self.state.frames, y, Want::Hessian, &Terms::ALL)
        {
            Ok(r) => Vgh {
                value: r.value(),
                hessian: r.dense_hessian(n).unwrap_or_else(|| DMatrix::zeros(n, n)),
                gradient: r.gradient.unwrap_or_else(|| DVector::zeros(n)),
            },
            Err(_) => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(n, f64::NAN),
                hessian: DMatrix::from_element(n, n, f64::NAN),
            },
        }
    }
    fn fast_value(&self, y: &[f64]) -> f64 {
        self.tile()
            .evaluate(&self.state.frames, y, Want::Value, &Terms::ALL)
            .map(|r| r.value())
            .unwrap_or(f64::NAN)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let mut y = self.state.y.clone();
        let n = self.problem.pattern.len();
        let r = self.problem.pattern.radius;
        let (dx, dth, wind) = match i % 3 {
            0 => (0.0, 0.0, false),
            1 => (0.05 * r, 0.1, false),
            _ => (0.2 * r, 0.3, true),
        };
        for v in y.iter_mut().take(3 * n) {
            *v += rng.random_range(-dx..=dx);
        }
        for v in y.iter_mut().skip(3 * n) {
            *v += rng.random_range(-dth..=dth);
            if wind {
                *v += 2.0 * std::f64::consts::PI * rng.random_range(-1..=1) as f64;
            }
        }
        y
    }
}

/// The reduced energy E(C̃y + d̃) of one pattern under three strains; the last input of a case (a fixed
/// parameter) selects the strain.
pub struct ReducedEnergyCheck {
    name: String,
    strains: Vec<StrainCase>,
}

impl ReducedEnergyCheck {
    fn case(&self, x: &[f64]) -> &StrainCase {
        &self.strains[x[x.len() - 1] as usize]
    }
}

impl Differentiable for ReducedEnergyCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        self.strains[0].dim()
    }
    fn n_params(&self) -> usize {
        1
    }
    /// 12 cases: each strain at its moved state and at both perturbation sizes (the AD Hessian over all 160
    /// unknowns dominates the harness time).
    fn cases(&self, requested: usize) -> usize {
        requested.min(12)
    }
    fn scales(&self) -> Scales {
        self.strains[0].scales()
    }
    fn input_scale(&self, i: usize) -> f64 {
        self.strains[0].input_scale(i)
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        self.case(x).kink_distance_of(x, i)
    }
    fn reference<D: Real>(&self, y: &[D]) -> D {
        let k = y[y.len() - 1].re() as usize;
        self.strains[k].reference(y)
    }
    fn fast(&self, y: &[f64]) -> Vgh {
        self.case(y).fast(&y[..self.dim()])
    }
    fn fast_value(&self, y: &[f64]) -> f64 {
        self.case(y).fast_value(&y[..self.dim()])
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        // cycle through the strains, and within each through the perturbation sizes
        let k = i % self.strains.len();
        let mut y = self.strains[k].sample(rng, i / self.strains.len());
        y.push(k as f64);
        y
    }
}

/// The reduced-energy row on the embedded plain weave: in-plane, bending along ξ₁, bending along ξ₂.
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let m = YarnMaterial::default();
    let strains = [
        MacroStrain::in_plane(0.1, 0.2, -0.05),
        MacroStrain::new(0.05, 0.1, 0.0, 60.0, 0.0),
        MacroStrain::new(-0.05, -0.1, 0.02, 0.0, -50.0),
    ];
    crate::generate::harness_patterns()
        .into_iter()
        .map(|(name, p)| {
            Box::new(ReducedEnergyCheck {
                name: format!("micro E(Cy+d)[{name}; in-plane, bend-x, bend-y]"),
                strains: strains
                    .iter()
                    .map(|z| StrainCase::new(p.clone(), &m, *z))
                    .collect(),
            }) as Box<dyn Check>
        })
        .collect()
}
