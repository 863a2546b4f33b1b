//! From a scene to a simulation: material, mesh, selections, boundary conditions and settings.

use super::*;

impl Scene {
    /// Load the material, build the mesh and the simulation. `file` names the scene in errors; relative paths
    /// are resolved against `dir`.
    pub fn build(
        &self,
        file: &str,
        dir: &Path,
    ) -> Result<(Simulation, Vec<[usize; 3]>), ShellError> {
        self.validate(file)?;
        let material = if self.material == "default" {
            default_material()
        } else {
            let p = dir.join(&self.material);
            Material::load(&p).map_err(|source| ShellError::Material {
                file: file.to_string(),
                source,
            })?
        };
        let (mesh, x0) = match &self.mesh {
            MeshSpec::Rectangle {
                width,
                height,
                edge,
                perturb,
                seed,
            } => {
                let m = Mesh::rectangle(*width, *height, *edge, *perturb, *seed).map_err(|e| {
                    ShellError::SceneMesh {
                        file: file.to_string(),
                        source: Box::new(e),
                    }
                })?;
                let pl = &self.placement;
                let x0 = m.place(pl.origin, pl.u, pl.v);
                (m, x0)
            }
            MeshSpec::Obj { path, transform } => {
                let (mut m, x) = Mesh::load_obj(&dir.join(path))?;
                for r in m.rest.iter_mut() {
                    *r = r.map(|c| c * transform.scale);
                }
                (m, x.into_iter().map(|p| transform.apply(p)).collect())
            }
        };
        let stencils = mesh.stencils(self.fabric_angle_deg.to_radians())?;
        let tris: Vec<[usize; 3]> = stencils.iter().map(|s| [s.v[0], s.v[1], s.v[2]]).collect();
        let flags = ModelFlags {
            bending: self.model.bending,
            only_1d: self.model.only_1d,
            in_plane_only: self.model.in_plane_only,
            stiffness: self.model.stiffness,
            bending_scale: self.model.bending_scale,
            fold: self.model.fold_barrier,
            collapse: self.model.collapse_barrier,
        };
        let model = ElementModel::new(&material, &flags, self.psd);
        let handles = self.held_sets(&mesh, &x0, file)?;
        let settings = Settings {
            dt: self.dt,
            quasi_static: self.quasi_static,
            force_tol: self.solver.force_tol,
            max_newton: self.solver.max_newton,
            exact_first: self.solver.exact_first,
            gravity: self.gravity,
            drag: self.drag,
            thickness: self.contact.thickness,
            contact_stiffness: self.contact.stiffness,
            friction: self.contact.friction,
            friction_velocity: self.contact.friction_velocity,
            damping: self.damping,
            wind: self.wind,
            handle_stiffness: self.handle_stiffness,
            max_halvings: self.solver.max_halvings,
            time_tol: self.solver.time_tol,
            integrator: self.solver.integrator,
            substeps: self.solver.substeps,
        };
        let obstacles = self.obstacles(file, dir)?;
        let sim = Simulation::new(
            model,
            stencils,
            x0,
            Boundary {
                pinned: vec![],
                handles,
                obstacles,
                obstacle_motions: self
                    .obstacles
                    .iter()
                    .map(|o| o.motion().cloned().unwrap_or_default())
                    .collect(),
            },
            settings,
            self.model.mass,
        )
        .map_err(|e| ShellError::SceneSetup {
            file: file.to_string(),
            source: Box::new(e),
        })?;
        Ok((sim, tris))
    }

    /// Every held vertex set as a named [`Handle`], so that each reports its reaction: the handles under their
    /// names, then the pins as `pin0`, `pin1`, … (fixed). A set that selects no vertex is an error naming its
    /// field, and so is one holding a vertex another set holds too when they are hard constraints (with
    /// `handle_stiffness` each set pulls a shared vertex with its own spring, as ARCSim does).
    fn held_sets(
        &self,
        mesh: &Mesh,
        x0: &[[f64; 3]],
        file: &str,
    ) -> Result<Vec<Handle>, ShellError> {
        let mut sets: Vec<(String, Handle)> = Vec::new();
        for (i, h) in self.handles.iter().enumerate() {
            let field = format!("handles[{i}].select");
            let vertices = h.select.select_checked(mesh, x0, file, field.clone())?;
            let motion = h.motion();
            sets.push((
                field,
                Handle {
                    name: h.name.clone(),
                    vertices,
                    motion,
                },
            ));
        }
        for (i, sel) in self.pins.iter().enumerate() {
            let field = format!("pins[{i}]");
            let vertices = sel.select_checked(mesh, x0, file, field.clone())?;
            let name = format!("pin{i}");
            sets.push((
                field,
                Handle {
                    name,
                    vertices,
                    motion: Motion::fixed(),
                },
            ));
        }
        let mut holder: Vec<Option<usize>> = vec![None; mesh.len()];
        let hard = self.handle_stiffness.is_none();
        for (k, (field, h)) in sets.iter().enumerate().filter(|_| hard) {
            for &v in &h.vertices {
                if let Some(j) = holder[v] {
                    return Err(ShellError::scene(
                        file,
                        field,
                        format!("holds vertex {v}, which {} holds too", sets[j].0),
                    ));
                }
                holder[v] = Some(k);
            }
        }
        Ok(sets.into_iter().map(|(_, h)| h).collect())
    }

    /// The obstacles, with their meshes loaded, transformed and checked (errors name `obstacles[i]`).
    pub fn obstacles(&self, file: &str, dir: &Path) -> Result<Vec<Obstacle>, ShellError> {
        self.obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| {
                Ok(match o {
                    ObstacleSpec::Sphere { center, radius, .. } => Obstacle::Sphere {
                        center: *center,
                        radius: *radius,
                    },
                    ObstacleSpec::Plane { point, normal, .. } => Obstacle::Plane {
                        point: *point,
                        normal: *normal,
                    },
                    ObstacleSpec::Mesh {
                        path, transform, ..
                    } => {
                        let p = dir.join(path);
                        let (v, t) = load_obj_surface(&p).map_err(|e| ShellError::SceneMesh {
                            file: format!("{file}: obstacles[{i}]"),
                            source: Box::new(e),
                        })?;
                        let v = v.into_iter().map(|q| transform.apply(q)).collect();
                        let m = MeshObstacle::new(&p.display().to_string(), v, t).map_err(|e| {
                            ShellError::SceneMesh {
                                file: format!("{file}: obstacles[{i}]"),
                                source: Box::new(e),
                            }
                        })?;
                        Obstacle::Mesh(Box::new(m))
                    }
                })
            })
            .collect()
    }
}
