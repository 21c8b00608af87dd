//! Legacy VTK files (VTK User's Guide, "VTK file formats", ASCII legacy format) that ParaView opens:
//! the cylindrical cells as an UNSTRUCTURED_GRID with cell data, and particles as POLYDATA points.
//!
//! Each fluid cell is an annular sector. Its arc is approximated by straight segments of at most
//! 15°, so one cell becomes a few VTK cells (hexahedra; wedges in the central annulus, whose inner
//! radius is the axis). The sub-cells carry their parent's values and its index as `cell_id`.

use crate::grid::CylGrid;
use crate::sim::snapshot::{ParticleSnapshot, Snapshot};
use std::fmt::Write;

/// Largest angle of one straight segment of a cell's arc.
const MAX_SEGMENT_RAD: f64 = std::f64::consts::PI / 12.0;
const VTK_WEDGE: u8 = 13;
const VTK_HEXAHEDRON: u8 = 12;

/// A named per-cell array.
pub enum CellField<'a> {
    Scalars(&'a str, &'a [f64]),
    Vectors(&'a str, &'a [[f64; 3]]),
}

/// Number of straight segments used for the arc of a cell in annulus i.
pub fn segments(grid: &CylGrid, i: usize) -> usize {
    (grid.dtheta(i) / MAX_SEGMENT_RAD).ceil().max(1.0) as usize
}

/// The cells as VTK sees them: points, per-cell point lists and kinds, and each VTK cell's fluid
/// cell (`parent`).
pub struct Geometry {
    pub points: Vec<[f64; 3]>,
    pub conn: Vec<Vec<usize>>,
    pub kinds: Vec<u8>,
    pub parent: Vec<usize>,
}

/// The grid's cells split into hexahedra and wedges (see the module comment).
pub fn geometry(grid: &CylGrid) -> Geometry {
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut conn: Vec<Vec<usize>> = Vec::new();
    let mut kinds: Vec<u8> = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    for k in 0..grid.nz {
        let (z0, z1) = (k as f64 * grid.dz, (k + 1) as f64 * grid.dz);
        for i in 0..grid.nr {
            let (r0, r1) = (i as f64 * grid.dr, (i + 1) as f64 * grid.dr);
            let s = segments(grid, i);
            for j in 0..grid.cells_in_annulus(i) {
                let (ta, tb) = grid.theta_bounds(i, j);
                for m in 0..s {
                    let t0 = ta + (tb - ta) * m as f64 / s as f64;
                    let t1 = ta + (tb - ta) * (m + 1) as f64 / s as f64;
                    let at = |r: f64, t: f64, z: f64| [r * t.cos(), r * t.sin(), z];
                    let base = points.len();
                    if i == 0 {
                        for z in [z0, z1] {
                            points.extend([[0.0, 0.0, z], at(r1, t0, z), at(r1, t1, z)]);
                        }
                        conn.push((base..base + 6).collect());
                        kinds.push(VTK_WEDGE);
                    } else {
                        for z in [z0, z1] {
                            points.extend([at(r0, t0, z), at(r1, t0, z), at(r1, t1, z), at(r0, t1, z)]);
                        }
                        conn.push((base..base + 8).collect());
                        kinds.push(VTK_HEXAHEDRON);
                    }
                    parent.push(grid.index(i, j, k));
                }
            }
        }
    }
    Geometry { points, conn, kinds, parent }
}

/// The grid with the given cell fields (each of length `grid.num_cells()`).
pub fn cells(grid: &CylGrid, title: &str, fields: &[CellField]) -> String {
    let Geometry { points, conn, kinds, parent } = geometry(grid);
    let mut out = String::new();
    let _ = writeln!(out, "# vtk DataFile Version 3.0\n{}\nASCII\nDATASET UNSTRUCTURED_GRID", one_line(title));
    let _ = writeln!(out, "POINTS {} double", points.len());
    for p in &points {
        let _ = writeln!(out, "{} {} {}", p[0], p[1], p[2]);
    }
    let size: usize = conn.iter().map(|c| c.len() + 1).sum();
    let _ = writeln!(out, "CELLS {} {}", conn.len(), size);
    for c in &conn {
        let _ = write!(out, "{}", c.len());
        for v in c {
            let _ = write!(out, " {v}");
        }
        out.push('\n');
    }
    let _ = writeln!(out, "CELL_TYPES {}", kinds.len());
    for k in &kinds {
        let _ = writeln!(out, "{k}");
    }
    let _ = writeln!(out, "CELL_DATA {}\nSCALARS cell_id int 1\nLOOKUP_TABLE default", parent.len());
    for p in &parent {
        let _ = writeln!(out, "{p}");
    }
    for f in fields {
        match f {
            CellField::Scalars(name, v) => {
                let _ = writeln!(out, "SCALARS {name} double 1\nLOOKUP_TABLE default");
                for p in &parent {
                    let _ = writeln!(out, "{}", v[*p]);
                }
            }
            CellField::Vectors(name, v) => {
                let _ = writeln!(out, "VECTORS {name} double");
                for p in &parent {
                    let _ = writeln!(out, "{} {} {}", v[*p][0], v[*p][1], v[*p][2]);
                }
            }
        }
    }
    out
}

/// The snapshot's cell fields: voidage (stored, or from particles by the direct method),
/// pressure_pa, gas_velocity_m_s (Cartesian), whichever exist.
pub fn snapshot_cells(s: &Snapshot) -> String {
    let grid = s.grid.grid();
    let voidage = super::fields::voidage(s);
    let velocity = super::fields::gas_velocity_cartesian(s);
    let mut fields = Vec::new();
    if let Some(v) = &voidage {
        fields.push(CellField::Scalars("voidage", v));
    }
    if let Some(p) = &s.pressure_pa {
        fields.push(CellField::Scalars("pressure_pa", p));
    }
    if let Some(u) = &velocity {
        fields.push(CellField::Vectors("gas_velocity_m_s", u));
    }
    cells(&grid, &format!("fluidbed snapshot {} t={} s step {}", s.index, s.time_s, s.step), &fields)
}

/// Particles as points with `radius_m` and `velocity_m_s` point data.
pub fn particles(p: &ParticleSnapshot, title: &str) -> String {
    let n = p.positions_m.len();
    let mut out = String::new();
    let _ = writeln!(out, "# vtk DataFile Version 3.0\n{}\nASCII\nDATASET POLYDATA", one_line(title));
    let _ = writeln!(out, "POINTS {n} double");
    for x in &p.positions_m {
        let _ = writeln!(out, "{} {} {}", x[0], x[1], x[2]);
    }
    let _ = writeln!(out, "VERTICES {} {}", n, 2 * n);
    for i in 0..n {
        let _ = writeln!(out, "1 {i}");
    }
    let _ = writeln!(out, "POINT_DATA {n}\nSCALARS radius_m double 1\nLOOKUP_TABLE default");
    for _ in 0..n {
        let _ = writeln!(out, "{}", p.radius_m);
    }
    let _ = writeln!(out, "VECTORS velocity_m_s double");
    for v in &p.velocities_m_s {
        let _ = writeln!(out, "{} {} {}", v[0], v[1], v[2]);
    }
    out
}

fn one_line(s: &str) -> String {
    s.chars().map(|c| if c == '\n' || c == '\r' { ' ' } else { c }).take(250).collect()
}
