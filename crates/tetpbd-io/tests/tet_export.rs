//! The `tet_export` binary writes one OBJ and one VTU per frame and reports read errors.

use std::process::Command;

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd_io::{write_msh, write_tetgen};

#[test]
fn exports_frames_and_reports_errors() {
    let dir = std::env::temp_dir().join(format!("tetpbd-io-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = box_grid(Vector3::new(0.2, 0.4, 0.2), [2, 4, 2], CellSplit::Six).unwrap();
    let (node, ele) = write_tetgen(&mesh);
    std::fs::write(dir.join("col.node"), node).unwrap();
    std::fs::write(dir.join("col.ele"), ele).unwrap();
    std::fs::write(dir.join("col.msh"), write_msh(&mesh)).unwrap();
    for input in ["col.node", "col.msh"] {
        let out = dir.join(format!("frames-{input}"));
        let run = Command::new(env!("CARGO_BIN_EXE_tet_export"))
            .arg(dir.join(input))
            .arg(&out)
            .args(["--frames", "3"])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success(), "{stdout}");
        assert!(stdout.starts_with("9 vertices pinned"), "{stdout}");
        assert!(stdout.contains("frame 3: 0 inverted"), "{stdout}");
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names.len(), 8, "{names:?}");
        assert_eq!(names[0], "surface_0000.obj");
        assert_eq!(names[7], "tets_0003.vtu");
        let vtu = std::fs::read_to_string(out.join("tets_0003.vtu")).unwrap();
        assert!(vtu.contains("NumberOfPoints=\"45\" NumberOfCells=\"96\""));
    }
    std::fs::write(dir.join("bad.node"), "4 3 0 0\n0 0 0 0\n").unwrap();
    std::fs::write(dir.join("bad.ele"), "").unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_tet_export"))
        .arg(dir.join("bad.node"))
        .arg(dir.join("unused"))
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains(".node line 2: input ends after 1 of 4 point rows"),
        "{stderr}"
    );
    // A bad option is named, not parsed as something else.
    let run = Command::new(env!("CARGO_BIN_EXE_tet_export"))
        .arg(dir.join("col.node"))
        .arg(dir.join("unused"))
        .arg("--compliance=-1")
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("--compliance"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
