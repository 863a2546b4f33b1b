//! The default material along a strain line (`docs/material.md`, "Material ψ(z)"): ψ(t d) and the directional
//! derivative dψ/dt = ∇ψ(t d)·d for t from −1 to 1, as CSV on standard output.
//!
//! `cargo run --release --example material_curve -- [COMPONENT] [POINTS] [> curve.csv]`: COMPONENT one of `s_x`,
//! `s_a`, `s_y`, `II00`, `II11` (default `s_x`): d is that component's unit vector scaled by its strain scale σ_k, so
//! the line spans the material's fitted range; POINTS (default 21) along it.

use hylc::material::synthetic::default_material;
use hylc::strain::StrainComponent;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let component: StrainComponent = args.next().as_deref().unwrap_or("s_x").parse()?;
    let points: usize = args.next().as_deref().unwrap_or("21").parse()?;
    if points < 2 {
        return Err("POINTS: at least 2".into());
    }

    let material = default_material();
    // the direction: σ_k along component k (index6: the place of k in the shell's six-component strain)
    let k = component.index6();
    let mut d = [0.0; 6];
    d[k] = material.strain_scale[component.index()];

    println!("t,{component},psi,dpsi_dt");
    for i in 0..points {
        let t = -1.0 + 2.0 * i as f64 / (points - 1) as f64;
        let z = d.map(|x| t * x);
        let e = material.eval(&z); // ψ (J/m²), ∇ψ, ∇²ψ
        let slope: f64 = (0..6).map(|j| e.grad[j] * d[j]).sum();
        println!("{t:.4},{:.6e},{:.6e},{:.6e}", z[k], e.value, slope);
    }
    Ok(())
}
