//! Frames as VTK unstructured grids (`.vtu`, ASCII XML) that ParaView and VisIt open, and the series of a run as
//! a ParaView collection (`.pvd`: every frame with its time), so that a run can be played and coloured by its
//! energy density, any strain component or the velocity.
//!
//! Cell data of [`Simulation::triangle_fields`]: `psi` = E_Δ / A (J/m², the triangle's energy per rest area,
//! barriers included) and `strain` (6 components: s_x, s_a, s_y, II₀₀, II₀₁, II₁₁, `docs/cloth-simulator.md`);
//! point data `velocity` (m/s).

use super::solver::Simulation;
use super::strain::StrainChain;
use crate::shell::assemble::gather;
use std::io::Write;
use std::path::Path;

/// A named field with `components` numbers per triangle (cell data) or per vertex (point data).
pub struct CellField<'a> {
    /// the field's name
    pub name: &'a str,
    /// numbers per cell or point
    pub components: usize,
    /// the numbers, `components` per cell or point
    pub values: &'a [f64],
}

/// Write `x` and `tris` with the cell fields and the point fields as a `.vtu` file.
pub fn write_vtu(
    path: &Path,
    x: &[[f64; 3]],
    tris: &[[usize; 3]],
    fields: &[CellField],
    point_fields: &[CellField],
) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "<?xml version=\"1.0\"?>")?;
    writeln!(
        f,
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">"
    )?;
    writeln!(f, "<UnstructuredGrid>")?;
    writeln!(
        f,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        x.len(),
        tris.len()
    )?;
    writeln!(
        f,
        "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for p in x {
        writeln!(f, "{} {} {}", p[0], p[1], p[2])?;
    }
    writeln!(f, "</DataArray></Points>")?;
    writeln!(f, "<Cells>")?;
    writeln!(
        f,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )?;
    for t in tris {
        writeln!(f, "{} {} {}", t[0], t[1], t[2])?;
    }
    writeln!(f, "</DataArray>")?;
    writeln!(
        f,
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    for k in 0..tris.len() {
        writeln!(f, "{}", 3 * (k + 1))?;
    }
    writeln!(f, "</DataArray>")?;
    // VTK_TRIANGLE = 5
    writeln!(
        f,
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )?;
    for _ in tris {
        writeln!(f, "5")?;
    }
    writeln!(f, "</DataArray>")?;
    writeln!(f, "</Cells>")?;
    for (tag, list) in [("CellData", fields), ("PointData", point_fields)] {
        writeln!(f, "<{tag}>")?;
        for c in list {
            write_array(&mut f, c)?;
        }
        writeln!(f, "</{tag}>")?;
    }
    writeln!(f, "</Piece></UnstructuredGrid></VTKFile>")?;
    f.flush()
}

/// One `<DataArray>` of a field, a row per triangle or vertex.
fn write_array(f: &mut impl Write, c: &CellField) -> std::io::Result<()> {
    writeln!(
        f,
        "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">",
        c.name, c.components
    )?;
    for row in c.values.chunks(c.components) {
        let row: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        writeln!(f, "{}", row.join(" "))?;
    }
    writeln!(f, "</DataArray>")
}

/// Write a ParaView collection of `(time, file)` frames (file names relative to the collection's folder).
pub fn write_pvd(path: &Path, frames: &[(f64, String)]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "<?xml version=\"1.0\"?>")?;
    writeln!(
        f,
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"
    )?;
    writeln!(f, "<Collection>")?;
    for (t, file) in frames {
        writeln!(
            f,
            "<DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        )?;
    }
    writeln!(f, "</Collection>")?;
    writeln!(f, "</VTKFile>")?;
    f.flush()
}

impl Simulation {
    /// Per triangle at the current state: ψ = E_Δ / A (J/m², NaN where the element is undefined) and the
    /// strain z (6 components, flattened).
    pub fn triangle_fields(&self) -> (Vec<f64>, Vec<f64>) {
        let mut psi = Vec::with_capacity(self.stencils.len());
        let mut z = Vec::with_capacity(6 * self.stencils.len());
        for st in &self.stencils {
            let q = gather(st, &self.x);
            let flaps = if self.model.bending {
                st.flaps
            } else {
                [false; 3]
            };
            let e = self.model.energy(&q, &st.rest, st.flaps);
            psi.push(e.map_or(f64::NAN, |e| e / st.rest.area));
            match StrainChain::new(&q, &st.rest, flaps) {
                Some(ch) => z.extend_from_slice(&ch.z),
                None => z.extend_from_slice(&[f64::NAN; 6]),
            }
        }
        (psi, z)
    }

    /// Write the current state as a `.vtu` frame with `psi` and `strain` per triangle and `velocity` per vertex.
    pub fn write_vtu(&self, path: &Path, tris: &[[usize; 3]]) -> std::io::Result<()> {
        let (psi, z) = self.triangle_fields();
        let fields = [
            CellField {
                name: "psi",
                components: 1,
                values: &psi,
            },
            CellField {
                name: "strain",
                components: 6,
                values: &z,
            },
        ];
        let velocity = [CellField {
            name: "velocity",
            components: 3,
            values: &self.v,
        }];
        write_vtu(path, &self.positions(), tris, &fields, &velocity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles: the counts, offsets, types and one field's rows are where a VTK reader looks for them.
    #[test]
    fn a_vtu_file_has_the_counts_and_arrays() {
        let dir = std::env::temp_dir().join(format!("hylc-vtu-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("t.vtu");
        let x = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let tris = [[0, 1, 2], [1, 3, 2]];
        let psi = [0.5, 1.5];
        let fields = [CellField {
            name: "psi",
            components: 1,
            values: &psi,
        }];
        let v = [0.0, 0.0, 1.0].repeat(4);
        let vel = [CellField {
            name: "velocity",
            components: 3,
            values: &v,
        }];
        write_vtu(&f, &x, &tris, &fields, &vel).unwrap();
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(text.contains("NumberOfPoints=\"4\" NumberOfCells=\"2\""));
        assert!(text.contains("Name=\"offsets\" format=\"ascii\">\n3\n6\n</DataArray>"));
        assert!(text.contains("Name=\"types\" format=\"ascii\">\n5\n5\n</DataArray>"));
        assert!(
            text.contains("Name=\"psi\" NumberOfComponents=\"1\" format=\"ascii\">\n0.5\n1.5\n")
        );
        assert!(text.contains("1 3 2\n"));
        assert!(text.contains(
            "<PointData>\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\""
        ));
        let pvd = dir.join("t.pvd");
        write_pvd(&pvd, &[(0.0, "a.vtu".into()), (0.5, "b.vtu".into())]).unwrap();
        let text = std::fs::read_to_string(&pvd).unwrap();
        assert!(text.contains("<DataSet timestep=\"0.5\" group=\"\" part=\"0\" file=\"b.vtu\"/>"));
    }
}
