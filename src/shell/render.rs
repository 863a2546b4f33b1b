//! A small software rasteriser for snapshots of a simulated cloth (`docs/layout.md`, "outputs other tools
//! open"): orthographic view from an azimuth and elevation, z-buffer, two-sided Lambert shading, 2× supersampling,
//! written as PNG. Obstacles are drawn as meshes ([`sphere_mesh`]) in their own colour.

use super::ShellError;
use crate::real::{cross, dot};
use std::path::Path;

/// Camera and image size of a snapshot.
#[derive(Clone, Copy, Debug)]
pub struct View {
    /// rotation about the world z axis of the viewing direction (degrees; 0 looks along +y)
    pub azimuth_deg: f64,
    /// angle of the viewing direction above the horizontal plane (degrees)
    pub elevation_deg: f64,
    /// image width (pixels)
    pub width: u32,
    /// image height (pixels)
    pub height: u32,
}

impl Default for View {
    fn default() -> Self {
        View {
            azimuth_deg: -35.0,
            elevation_deg: 30.0,
            width: 800,
            height: 600,
        }
    }
}

/// One triangle mesh to draw in one colour.
pub struct Layer<'a> {
    /// vertex positions (m)
    pub positions: &'a [[f64; 3]],
    /// triangles (vertex indices)
    pub triangles: &'a [[usize; 3]],
    /// fill colour (RGB)
    pub color: [u8; 3],
}

/// A UV sphere with `n` segments around and `n / 2` from pole to pole.
pub fn sphere_mesh(center: [f64; 3], radius: f64, n: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let n = n.max(6);
    let rings = n / 2;
    let mut x = Vec::with_capacity((rings + 1) * n);
    for i in 0..=rings {
        let th = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..n {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
            x.push([
                center[0] + radius * th.sin() * ph.cos(),
                center[1] + radius * th.sin() * ph.sin(),
                center[2] + radius * th.cos(),
            ]);
        }
    }
    let mut t = Vec::with_capacity(2 * rings * n);
    for i in 0..rings {
        for j in 0..n {
            let (a, b) = (i * n + j, i * n + (j + 1) % n);
            let (c, d) = (a + n, b + n);
            t.push([a, c, b]);
            t.push([b, c, d]);
        }
    }
    (x, t)
}

/// Camera basis: right, up, towards the viewer.
fn basis(view: &View) -> [[f64; 3]; 3] {
    let (a, e) = (
        view.azimuth_deg.to_radians(),
        view.elevation_deg.to_radians(),
    );
    // direction from the scene towards the camera
    let back = [-a.sin() * e.cos(), -a.cos() * e.cos(), e.sin()];
    let right = [a.cos(), -a.sin(), 0.0];
    let up = cross(&back, &right);
    [right, up, back]
}

/// Render the layers into an RGB image (row-major, `width × height × 3`); the view is fitted to the bounding
/// box of every layer with a 5 % margin. Pixels no triangle covers are white.
pub fn render(layers: &[Layer], view: &View) -> Vec<u8> {
    const SS: usize = 2;
    let (w, h) = (view.width as usize * SS, view.height as usize * SS);
    let [right, up, back] = basis(view);
    let project = |p: [f64; 3]| [dot(&p, &right), dot(&p, &up), dot(&p, &back)];
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for l in layers {
        for &p in l.positions {
            let q = project(p);
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
    }
    let mut rgb = vec![255u8; w * h * 3];
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    if lo[0].is_finite() {
        let span = ((hi[0] - lo[0]) / w as f64)
            .max((hi[1] - lo[1]) / h as f64)
            .max(1e-12)
            * 1.1;
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let light = {
            let l = [
                0.4 * right[0] + 0.6 * up[0] + back[0],
                0.4 * right[1] + 0.6 * up[1] + back[1],
                0.4 * right[2] + 0.6 * up[2] + back[2],
            ];
            let n = dot(&l, &l).sqrt();
            l.map(|v| v / n)
        };
        for l in layers {
            let px: Vec<[f64; 3]> = l
                .positions
                .iter()
                .map(|&p| {
                    let q = project(p);
                    [
                        (q[0] - c[0]) / span + 0.5 * w as f64,
                        0.5 * h as f64 - (q[1] - c[1]) / span,
                        q[2],
                    ]
                })
                .collect();
            for t in l.triangles {
                let [a, b, d] = t.map(|i| l.positions[i]);
                let n = cross(
                    &[b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    &[d[0] - a[0], d[1] - a[1], d[2] - a[2]],
                );
                let nn = dot(&n, &n).sqrt();
                if nn == 0.0 {
                    continue;
                }
                let shade = 0.3 + 0.7 * (dot(&n, &light) / nn).abs();
                let color = l.color.map(|v| (v as f64 * shade).round().min(255.0) as u8);
                fill_triangle(t.map(|i| px[i]), color, w, h, &mut rgb, &mut depth);
            }
        }
    }
    // box filter down to the output size
    let (ow, oh) = (view.width as usize, view.height as usize);
    let mut out = vec![0u8; ow * oh * 3];
    for y in 0..oh {
        for x in 0..ow {
            for ch in 0..3 {
                let mut s = 0u32;
                for dy in 0..SS {
                    for dx in 0..SS {
                        s += rgb[((y * SS + dy) * w + x * SS + dx) * 3 + ch] as u32;
                    }
                }
                out[(y * ow + x) * 3 + ch] = (s / (SS * SS) as u32) as u8;
            }
        }
    }
    out
}

/// Scan-convert one projected triangle (x, y in pixels, depth towards the viewer) with a z-buffer.
fn fill_triangle(
    p: [[f64; 3]; 3],
    color: [u8; 3],
    w: usize,
    h: usize,
    rgb: &mut [u8],
    depth: &mut [f64],
) {
    let area =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if area.abs() < 1e-12 {
        return;
    }
    let x0 = p
        .iter()
        .map(|q| q[0])
        .fold(f64::INFINITY, f64::min)
        .floor()
        .max(0.0) as usize;
    let x1 = (p
        .iter()
        .map(|q| q[0])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as isize)
        .clamp(0, w as isize - 1) as usize;
    let y0 = p
        .iter()
        .map(|q| q[1])
        .fold(f64::INFINITY, f64::min)
        .floor()
        .max(0.0) as usize;
    let y1 = (p
        .iter()
        .map(|q| q[1])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as isize)
        .clamp(0, h as isize - 1) as usize;
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (sx, sy) = (x as f64 + 0.5, y as f64 + 0.5);
            let edge = |a: [f64; 3], b: [f64; 3]| {
                (b[0] - a[0]) * (sy - a[1]) - (sx - a[0]) * (b[1] - a[1])
            };
            let l0 = edge(p[1], p[2]) / area;
            let l1 = edge(p[2], p[0]) / area;
            let l2 = 1.0 - l0 - l1;
            if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                continue;
            }
            let z = l0 * p[0][2] + l1 * p[1][2] + l2 * p[2][2];
            let i = y * w + x;
            if z > depth[i] {
                depth[i] = z;
                rgb[3 * i..3 * i + 3].copy_from_slice(&color);
            }
        }
    }
}

/// Render and write a PNG.
pub fn write_png(path: &Path, layers: &[Layer], view: &View) -> Result<(), ShellError> {
    let rgb = render(layers, view);
    image::save_buffer(path, &rgb, view.width, view.height, image::ColorType::Rgb8).map_err(
        |source| ShellError::Png {
            path: path.to_path_buf(),
            source,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square seen from straight above fills the middle of the image in its colour, and a sphere in
    /// front of it hides it where they overlap.
    #[test]
    fn square_from_above_and_occlusion() {
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = [[0, 1, 2], [0, 2, 3]];
        let view = View {
            azimuth_deg: 0.0,
            elevation_deg: 90.0,
            width: 100,
            height: 100,
        };
        let img = render(
            &[Layer {
                positions: &x,
                triangles: &t,
                color: [200, 0, 0],
            }],
            &view,
        );
        let px = |img: &[u8], x: usize, y: usize| {
            [
                img[(y * 100 + x) * 3],
                img[(y * 100 + x) * 3 + 1],
                img[(y * 100 + x) * 3 + 2],
            ]
        };
        // seen face-on with the light 30° off the normal: shade 0.3 + 0.7 cos
        let c = px(&img, 50, 50);
        assert!(c[0] > 150 && c[1] == 0 && c[2] == 0, "{c:?}");
        assert_eq!(px(&img, 1, 1), [255, 255, 255], "the margin is background");
        let (sx, st) = sphere_mesh([0.5, 0.5, 0.5], 0.2, 24);
        let img = render(
            &[
                Layer {
                    positions: &x,
                    triangles: &t,
                    color: [200, 0, 0],
                },
                Layer {
                    positions: &sx,
                    triangles: &st,
                    color: [0, 0, 200],
                },
            ],
            &view,
        );
        let c = px(&img, 50, 50);
        assert!(
            c[2] > 100 && c[0] == 0,
            "the sphere above the square hides it: {c:?}"
        );
        let c = px(&img, 12, 50);
        assert!(
            c[0] > 100 && c[2] == 0,
            "the square outside the sphere: {c:?}"
        );
    }
}
