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
        "cells_000002.vtk",
        "particles_000002.vtk",
        "cells.pvd",
        "voidage_last.png",
        "mean_particle_height.png",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    let png = std::fs::read(out.join("voidage_last.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
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
