use super::*;
use crate::grid::CylGrid;
use crate::sim::snapshot::{GridInfo, ParticleSnapshot, Snapshot};

fn snapshot_with_particles(positions: Vec<[f64; 3]>) -> Snapshot {
    let grid = CylGrid::new(0.022, 0.06, 0.0044, 0.005, 3);
    let n = positions.len();
    Snapshot {
        index: 0,
        time_s: 0.0,
        step: 0,
        grid: GridInfo::of(&grid),
        voidage: None,
        pressure_pa: None,
        gas_velocity_m_s: None,
        pressure_drop_pa: None,
        layer_pressure_drop_pa: None,
        particles: Some(ParticleSnapshot {
            radius_m: 0.0006,
            positions_m: positions,
            velocities_m_s: vec![[0.0; 3]; n],
        }),
    }
}

#[test]
fn npy_header_is_aligned_to_64_bytes_and_round_trips() {
    let data: Vec<f64> = (0..12).map(|x| x as f64 * 0.5 - 1.0).collect();
    let bytes = npy::encode_f64(&[3, 4], &data);
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + hlen) % 64, 0, "NEP 1: data starts on a 64-byte boundary");
    assert_eq!(bytes[10 + hlen - 1], b'\n');
    assert_eq!(bytes.len(), 10 + hlen + 8 * 12);
    assert_eq!(npy::decode_f64(&bytes), Some((vec![3, 4], data)));
}

#[test]
fn png_crc_matches_the_specification_value_for_iend() {
    // The IEND chunk's CRC is fixed by the PNG specification: AE 42 60 82.
    assert_eq!(png::crc32(b"IEND"), 0xAE42_6082);
    let img = png::Image::new(3, 2, [1, 2, 3]);
    let bytes = img.encode();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[bytes.len() - 4..], &[0xAE, 0x42, 0x60, 0x82]);
}

#[test]
fn direct_voidage_conserves_particle_volume() {
    // Σ(1 − ε)·V_cell = N·V_p (paper eq. 2 puts each particle whole into one cell).
    let positions: Vec<[f64; 3]> = (0..200)
        .map(|n| {
            let t = n as f64 * 0.7;
            [0.015 * (n as f64 / 200.0) * t.cos(), 0.015 * (n as f64 / 200.0) * t.sin(), 0.001 + 0.0002 * n as f64]
        })
        .collect();
    let s = snapshot_with_particles(positions);
    let eps = fields::voidage(&s).expect("voidage from particles");
    let vc = s.grid.cell_volume_m3;
    let solid: f64 = eps.iter().map(|e| (1.0 - e) * vc).sum();
    let vp = std::f64::consts::PI * 0.0012f64.powi(3) / 6.0;
    assert!((solid - 200.0 * vp).abs() < 1e-12 * 200.0 * vp * 100.0, "{solid} vs {}", 200.0 * vp);
    assert!(eps.iter().all(|e| (0.0..=1.0).contains(e)));
}

#[test]
fn vtk_grid_has_one_subcell_per_arc_segment_of_at_most_15_degrees() {
    // A circle cut into straight segments of angle φ has area ½R² n sin φ; here every annulus's
    // segments are polygons, so the summed hexahedron volume equals that sum, within 1 %.
    let grid = CylGrid::new(0.022, 0.06, 0.0044, 0.005, 3);
    let text = vtk::cells(&grid, "t", &[vtk::CellField::Scalars("voidage", &vec![1.0; grid.num_cells()])]);
    let n_sub: usize =
        (0..grid.nr).map(|i| grid.cells_in_annulus(i) * vtk::segments(&grid, i)).sum::<usize>() * grid.nz;
    assert!(text.contains(&format!("CELL_TYPES {n_sub}")));
    assert!(text.contains("SCALARS voidage double 1"));
    // Outer ring: segments of equal angle φ_i; polygon area = ½ r² · (number of segments) · sin φ.
    let outer = grid.nr - 1;
    let phi = grid.dtheta(outer) / vtk::segments(&grid, outer) as f64;
    let ratio = phi.sin() / phi;
    assert!(ratio > 0.99, "segments of {phi} rad keep the area within 1 %");
}

#[test]
fn axial_slice_shows_lower_voidage_where_particles_are() {
    let positions: Vec<[f64; 3]> =
        (0..400).map(|n| [0.0001 * (n % 20) as f64 - 0.001, 0.0001 * (n / 20) as f64, 0.002]).collect();
    let s = snapshot_with_particles(positions);
    let eps = fields::voidage(&s).expect("voidage");
    let labels = plot::FieldLabels { title: "t", quantity: "voidage ε [-]", lo: 0.0, hi: 1.0 };
    let img = plot::axial_slice(&s.grid.grid(), &eps, &labels).expect("drawn");
    let empty = img.rgb.iter().filter(|p| **p == plot::colour(1.0)).count();
    let min = eps.iter().cloned().fold(1.0, f64::min);
    let packed = img.rgb.iter().filter(|p| **p == plot::colour(min)).count();
    assert!(min < 0.9, "the particles fill a cell ({min})");
    assert!(
        empty > 10 * packed && packed > 0,
        "empty cells are ε = 1 ({empty} px), the packed one shows ({packed} px)"
    );
}
