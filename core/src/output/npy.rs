//! NumPy `.npy` format version 1.0 (numpy.org, "NEP 1: a simple file format for NumPy arrays"):
//! magic `\x93NUMPY`, version 1.0, a little-endian u16 header length, a Python-dict header padded
//! with spaces to a multiple of 64 bytes and ending in `\n`, then the raw little-endian data.

/// Encode `data` (row-major, C order) as a float64 array of the given shape.
pub fn encode_f64(shape: &[usize], data: &[f64]) -> Vec<u8> {
    let count: usize = shape.iter().product();
    assert_eq!(count, data.len(), "npy shape {shape:?} does not match {} values", data.len());
    let dims = match shape.len() {
        1 => format!("({},)", shape[0]),
        _ => format!("({})", shape.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {dims}, }}");
    // magic (6) + version (2) + length (2) + header + '\n' must be a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for x in data {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// Decode a float64 `.npy` written by [`encode_f64`] (C order): (shape, data).
pub fn decode_f64(bytes: &[u8]) -> Option<(Vec<usize>, Vec<f64>)> {
    if bytes.len() < 10 || &bytes[..8] != b"\x93NUMPY\x01\x00" {
        return None;
    }
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(bytes.get(10..10 + hlen)?).ok()?;
    if !header.contains("'<f8'") || !header.contains("'fortran_order': False") {
        return None;
    }
    let s = header.split("'shape': (").nth(1)?.split(')').next()?;
    let shape: Vec<usize> =
        s.split(',').map(str::trim).filter(|t| !t.is_empty()).map(|t| t.parse().ok()).collect::<Option<_>>()?;
    let data: Vec<f64> =
        bytes[10 + hlen..].chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect();
    (data.len() == shape.iter().product::<usize>()).then_some((shape, data))
}
