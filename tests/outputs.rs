//! What a run leaves for other tools (docs/cloth-simulator.md, "Outputs"): `provenance.json` beside the frames
//! (hylc's version, the commit, the command line) and the same in every OBJ's header, `.vtu` frames with ψ and
//! the six strains per triangle and the velocity per vertex with their series `frames.pvd` when asked for, and
//! `hylc --version` naming the commit. (The Python tests read the series back with meshio.)

use serde_json::Value;
use std::process::Command;

fn hylc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .expect("run hylc");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// The numbers of a `<DataArray … Name="NAME" …>` block of a VTU file.
fn array(text: &str, name: &str) -> Vec<f64> {
    let start = text.find(&format!("Name=\"{name}\"")).expect(name);
    let body = &text[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn simulate_writes_provenance_and_vtu_frames() {
    let dir = std::env::temp_dir().join(format!("hylc-outputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let args = [
        "simulate",
        "stretch-x",
        "--edge",
        "0.025",
        "--duration",
        "0.0334",
        "--format",
        "vtu",
        "--quiet",
        "--out",
        o,
    ];
    let (code, stdout, stderr) = hylc(&args);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let p: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("provenance.json")).unwrap())
            .unwrap();
    assert_eq!(p["hylc"], env!("CARGO_PKG_VERSION"));
    assert!(!p["commit"].as_str().unwrap().is_empty());
    let command: Vec<&str> = p["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(&command[1..], &args[..]);
    let pvd = std::fs::read_to_string(out.join("frames.pvd")).unwrap();
    assert!(
        pvd.contains("timestep=\"0\" group=\"\" part=\"0\" file=\"frame_0000.vtu\""),
        "{pvd}"
    );
    for k in 0..=2 {
        let obj = std::fs::read_to_string(out.join(format!("frame_{k:04}.obj"))).unwrap();
        assert!(
            obj.starts_with(&format!("# hylc {}", env!("CARGO_PKG_VERSION"))),
            "{obj}"
        );
        assert!(obj.contains("simulate stretch-x"));
        let text = std::fs::read_to_string(out.join(format!("frame_{k:04}.vtu"))).unwrap();
        let cells: usize = {
            let s = text.find("NumberOfCells=\"").unwrap() + 15;
            text[s..s + text[s..].find('"').unwrap()].parse().unwrap()
        };
        let psi = array(&text, "psi");
        let strain = array(&text, "strain");
        let points = text.matches('\n').count(); // an upper bound; the exact count below
        let s = text.find("NumberOfPoints=\"").unwrap() + 16;
        let n: usize = text[s..s + text[s..].find('"').unwrap()].parse().unwrap();
        assert!(n < points);
        assert_eq!(array(&text, "velocity").len(), 3 * n);
        assert_eq!(psi.len(), cells);
        assert_eq!(strain.len(), 6 * cells);
        assert!(psi.iter().all(|v| v.is_finite()));
        // the initial frame is the flat rest state; the pulled ones are stretched along x
        let sx_max = strain.chunks(6).map(|z| z[0]).fold(f64::MIN, f64::max);
        if k == 0 {
            assert!(sx_max.abs() < 1e-12, "{sx_max}");
        } else {
            assert!(sx_max > 1e-5, "frame {k}: {sx_max}");
        }
    }
    let (code, version, _) = hylc(&["--version"]);
    assert_eq!(code, 0);
    assert!(
        version.contains(env!("CARGO_PKG_VERSION")) && version.contains("commit"),
        "{version}"
    );
}
