//! The CLI: `fluidbed run` on its embedded server leaves CSV, NPY, VTK and PNG results; exit
//! codes tell an invalid case (2) and an unreachable server (4) apart.

use fluidbed_tests::*;

#[test]
fn run_with_embedded_server_leaves_csv_npy_vtk_and_png() {
    let dir = TempDir::new("cli");
    let case = dir.path().join("tiny.json");
    std::fs::write(&case, lattice_case(3, 2, 0.01, 0.005).to_string()).unwrap();
    let out = dir.path().join("out");
    let code = fluidbed::cli::main_with([
        "fluidbed",
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--threads",
        "1",
    ]);
    assert_eq!(code, fluidbed::exit::OK);
    let csv = std::fs::read_to_string(out.join("pressure_drop.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3, "header and one row per snapshot");
    for f in [
        "voidage_000000.npy",
        "voidage_000002.npy",
        "cells_000002.vtu",
        "particles_000002.vtp",
        "cells.pvd",
        "voidage_last.png",
        "mean_particle_height.png",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    for file in ["voidage_last.png", "mean_particle_height.png"] {
        let png = Picture::decode(&std::fs::read(out.join(file)).unwrap());
        assert!(png.width >= 400 && png.height >= 250 && png.colours() > 20, "{file}: {}×{}", png.width, png.height);
    }
}

#[test]
fn exit_codes_tell_invalid_case_and_unreachable_server_apart() {
    let dir = TempDir::new("cli-codes");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, r#"{"particles": {"diameter_m": -1}}"#).unwrap();
    assert_eq!(fluidbed::cli::main_with(["fluidbed", "validate", bad.to_str().unwrap()]), fluidbed::exit::INVALID_CASE);
    assert_eq!(fluidbed::cli::main_with(["fluidbed", "run", bad.to_str().unwrap()]), fluidbed::exit::INVALID_CASE);
    let code = fluidbed::cli::main_with(["fluidbed", "--server", "http://127.0.0.1:9", "status", "abc"]);
    assert_eq!(code, fluidbed::exit::SERVER);
    assert_eq!(fluidbed::cli::main_with(["fluidbed", "no-such-verb"]), fluidbed::exit::USAGE);
}

#[test]
fn run_replaces_its_own_folder_refuses_others_and_folds_the_wal() {
    let dir = TempDir::new("cli-out");
    let case = dir.path().join("tiny.json");
    std::fs::write(&case, lattice_case(3, 2, 0.01, 0.005).to_string()).unwrap();
    let out = dir.path().join("out");
    let run = |out: &std::path::Path| {
        fluidbed::cli::main_with([
            "fluidbed",
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--threads",
            "1",
        ])
    };
    assert_eq!(run(&out), fluidbed::exit::OK);
    // The .pvd series lists VTK XML files that exist.
    let pvd = std::fs::read_to_string(out.join("cells.pvd")).unwrap();
    assert!(pvd.contains("file=\"cells_000002.vtu\""), "{pvd}");
    let vtu = std::fs::read(out.join("cells_000002.vtu")).unwrap();
    assert!(vtu.starts_with(b"<?xml") && String::from_utf8_lossy(&vtu).contains("vtkZLibDataCompressor"));
    // The embedded server folded its WAL into the database when it stopped.
    let wal = out.join("server-data").join("fluidbed.sqlite-wal");
    assert!(std::fs::metadata(&wal).map_or(true, |m| m.len() == 0), "WAL left: {wal:?}");

    // A second run into the same folder leaves no stale file of the first.
    std::fs::write(out.join("stale.npy"), b"old").unwrap();
    assert_eq!(run(&out), fluidbed::exit::OK);
    assert!(!out.join("stale.npy").exists());
    assert!(out.join("pressure_drop.csv").is_file());

    // A folder that `run` did not write is not touched.
    let other = dir.path().join("mine");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("thesis.tex"), b"keep me").unwrap();
    assert_eq!(run(&other), fluidbed::exit::USAGE);
    assert_eq!(std::fs::read(other.join("thesis.tex")).unwrap(), b"keep me");

    // `fetch` refuses an id that would leave its output folder.
    let code = fluidbed::cli::main_with(["fluidbed", "--server", "http://127.0.0.1:9", "fetch", "../../x"]);
    assert_eq!(code, fluidbed::exit::USAGE);
}
