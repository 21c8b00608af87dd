//! VTK XML files (VTK User's Guide, "XML File Formats"), which ParaView's .pvd reader opens: the
//! cells as an UnstructuredGrid (.vtu) and the particles as PolyData points (.vtp). Arrays are
//! binary, zlib-compressed, in the appended section: each array is a UInt64 header
//! [blocks = 1, block size, last block size, compressed size] followed by its zlib stream.
//! The cell geometry is the legacy writer's (`vtk::geometry`).

use super::vtk::geometry;
use crate::sim::snapshot::{ParticleSnapshot, Snapshot};
use std::fmt::Write;

/// Appended arrays: the XML `DataArray` elements and the bytes they point into.
#[derive(Default)]
struct Appended {
    xml: String,
    bytes: Vec<u8>,
}

impl Appended {
    /// Add one array: `kind` is the VTK type name, `raw` its little-endian values.
    fn array(&mut self, kind: &str, name: &str, components: usize, raw: &[u8]) {
        let packed = miniz_oxide::deflate::compress_to_vec_zlib(raw, 6);
        let _ = writeln!(
            self.xml,
            "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"appended\" offset=\"{}\"/>",
            self.bytes.len()
        );
        for h in [1u64, raw.len() as u64, raw.len() as u64, packed.len() as u64] {
            self.bytes.extend_from_slice(&h.to_le_bytes());
        }
        self.bytes.extend_from_slice(&packed);
    }
    fn f64s(&mut self, name: &str, components: usize, v: impl Iterator<Item = f64>) {
        self.array("Float64", name, components, &v.flat_map(f64::to_le_bytes).collect::<Vec<_>>());
    }
    fn i64s(&mut self, name: &str, v: impl Iterator<Item = i64>) {
        self.array("Int64", name, 1, &v.flat_map(i64::to_le_bytes).collect::<Vec<_>>());
    }
    /// Take the XML written so far (the next element's arrays start empty).
    fn take_xml(&mut self) -> String {
        std::mem::take(&mut self.xml)
    }
}

fn file(kind: &str, body: &str, appended: &[u8]) -> Vec<u8> {
    let mut out = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<{kind}>\n{body}</{kind}>\n\
         <AppendedData encoding=\"raw\">\n_"
    )
    .into_bytes();
    out.extend_from_slice(appended);
    out.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    out
}

/// The snapshot's cells (.vtu) with `cell_id`, voidage, pressure_pa and gas_velocity_m_s
/// (Cartesian), whichever exist, as cell data.
pub fn snapshot_cells(s: &Snapshot) -> Vec<u8> {
    let grid = s.grid.grid();
    let g = geometry(&grid);
    let mut a = Appended::default();
    a.f64s("points", 3, g.points.iter().flatten().copied());
    let points = a.take_xml();
    a.i64s("connectivity", g.conn.iter().flatten().map(|&v| v as i64));
    a.i64s(
        "offsets",
        g.conn.iter().scan(0i64, |end, c| {
            *end += c.len() as i64;
            Some(*end)
        }),
    );
    a.array("UInt8", "types", 1, &g.kinds);
    let cells = a.take_xml();
    a.i64s("cell_id", g.parent.iter().map(|&p| p as i64));
    if let Some(v) = super::fields::voidage(s) {
        a.f64s("voidage", 1, g.parent.iter().map(|&p| v[p]));
    }
    if let Some(v) = &s.pressure_pa {
        a.f64s("pressure_pa", 1, g.parent.iter().map(|&p| v[p]));
    }
    if let Some(u) = super::fields::gas_velocity_cartesian(s) {
        a.f64s("gas_velocity_m_s", 3, g.parent.iter().flat_map(|&p| u[p]));
    }
    let data = a.take_xml();
    let body = format!(
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n<Points>\n{points}</Points>\n<Cells>\n{cells}</Cells>\n\
         <CellData>\n{data}</CellData>\n</Piece>\n",
        g.points.len(),
        g.conn.len()
    );
    file("UnstructuredGrid", &body, &a.bytes)
}

/// Particles (.vtp) as vertices with `radius_m` and `velocity_m_s` point data.
pub fn particles(p: &ParticleSnapshot) -> Vec<u8> {
    let n = p.positions_m.len();
    let mut a = Appended::default();
    a.f64s("points", 3, p.positions_m.iter().flatten().copied());
    let points = a.take_xml();
    a.i64s("connectivity", 0..n as i64);
    a.i64s("offsets", 1..=n as i64);
    let verts = a.take_xml();
    a.f64s("radius_m", 1, std::iter::repeat_n(p.radius_m, n));
    a.f64s("velocity_m_s", 3, p.velocities_m_s.iter().flatten().copied());
    let data = a.take_xml();
    let body = format!(
        "<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n\
         <Points>\n{points}</Points>\n<Verts>\n{verts}</Verts>\n<PointData>\n{data}</PointData>\n</Piece>\n"
    );
    file("PolyData", &body, &a.bytes)
}
