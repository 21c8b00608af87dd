//! Seeded mutations of the shipped cases into hostile submissions: dropped, duplicated and
//! retyped fields, NaN/Inf-like tokens, huge, negative and zero numbers, deep nesting, huge
//! arrays, long and unicode strings, truncated JSON, wrong content types and huge bodies.

use serde_json::{json, Map, Value};

/// SplitMix64: small, seedable, the same sequence on every platform.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// One request body with its content type (None: no header) and what was done to it.
pub struct Submission {
    pub body: Vec<u8>,
    pub content_type: Option<&'static str>,
    pub label: String,
    /// The body as a JSON value when it is one (to judge a 422's pointers against).
    pub value: Option<Value>,
}

/// The submission that asks for 10^8 particles.
pub fn hundred_million_particles(base: &Value) -> Submission {
    let mut v = base.clone();
    v["bed"] = json!({ "generated": { "count": 100_000_000u64, "seed": 1 } });
    let body = v.to_string().into_bytes();
    Submission { body, content_type: Some("application/json"), label: "count 1e8".into(), value: Some(v) }
}

/// Raw tokens put where a value goes: not JSON, or JSON that tests the number parser.
const TOKENS: &[&str] = &[
    "NaN",
    "-NaN",
    "nan",
    "Infinity",
    "-Infinity",
    "inf",
    "1e999",
    "-1e999",
    "1e-999",
    "0x1F",
    "+1",
    ".5",
    "1.",
    "01",
    "-",
    "1e",
    "--1",
    "True",
    "None",
    "undefined",
    "'x'",
    "\"\\ud800\"",
    "\"\\u0000\"",
    "\"\\x41\"",
    "\"a\u{1}b\"",
    "123456789012345678901234567890",
    "-123456789012345678901234567890",
    "18446744073709551616",
    "-9223372036854775809",
    "1e308",
    "2.2250738585072014e-308",
    "5e-324",
    "-0",
    "-0.0",
    "/* c */ 1",
    "[1,]",
    "{\"a\":1,}",
    "{,}",
    "[,]",
    "\"\\uDC00\\uD800\"",
];

/// Numbers at the edges.
const NUMBERS: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    1.0,
    -1e308,
    1e308,
    1e-308,
    5e-324,
    -5e-324,
    1e19,
    -1e19,
    1.8446744073709552e19,
    9.3e18,
    4.3e9,
    1e8,
    1e12,
    1e-12,
    0.5,
    3.0,
    64.0,
    65.0,
    2.0,
    1e6,
    1e-6,
    f64::MAX,
    f64::MIN,
    f64::EPSILON,
    0.1,
    1e-300,
    1e300,
];

const STRINGS: &[&str] = &[
    "",
    " ",
    "direct",
    "grouping",
    "square_grid",
    "exact_cylindrical",
    "exact",
    "cuboid",
    "voidage",
    "pressure",
    "gas_velocity",
    "particles",
    "beetstra",
    "gidaspow",
    "di_felice",
    "hertz_mindlin",
    "linear_spring_dashpot",
    "Ωμέγα 流化床 🫧",
    "\u{202e}desrever",
    "\u{0}",
    "a\u{1}\u{7f}b",
    "\u{feff}",
    "💥💥💥",
    "../../etc/passwd",
    "'; DROP TABLE jobs; --",
    "<script>alert(1)</script>",
    "%s%n%x",
    "\\",
    "~0/~1",
];

/// Fields of the schema, put into cases that lack them (pointers; the value is chosen randomly).
const KNOWN: &[&str] = &[
    "/gas/time_step_s",
    "/gas/cfl_factor",
    "/gas/inlet_voidage",
    "/gas/outlet_relaxation",
    "/gas/temperature_k",
    "/gas/specific_gas_constant_j_kg_k",
    "/gas/superficial_velocity_m_s",
    "/grid/dz_m",
    "/grid/dr_m",
    "/grid/n0",
    "/bed/generated/count",
    "/bed/generated/settled_height_m",
    "/bed/generated/seed",
    "/bed/explicit/positions_m",
    "/bed/explicit/velocities_m_s",
    "/voidage/method",
    "/voidage/box_side_m",
    "/voidage/cube_side_factor",
    "/voidage/split",
    "/coupling/interval_steps",
    "/coupling/drag_law",
    "/dem/threads",
    "/dem/skin_fraction",
    "/dem/frozen",
    "/dem/reproducible",
    "/outputs/fields",
    "/outputs/checkpoint_interval_s",
    "/particles/contact_law",
    "/particles/contact_law/linear_spring_dashpot/normal_stiffness_n_m",
    "/particles/normal_damping/restitution",
    "/particles/tangential_damping/restitution",
    "/column/lid",
    "/gravity_m_s2",
    "/end_time_s",
];

const CONTENT_TYPES: &[Option<&str>] = &[
    None,
    Some("text/plain"),
    Some("application/xml"),
    Some("application/x-www-form-urlencoded"),
    Some("multipart/form-data; boundary=x"),
    Some("application/json; charset=utf-16"),
    Some("application/problem+json"),
    Some(""),
    Some("application/json, text/plain"),
    Some("*/*"),
    Some("application/octet-stream"),
    Some("APPLICATION/JSON"),
];

/// Every JSON pointer in `v` (the root excluded).
fn pointers(v: &Value, at: &str, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(x, &p, out);
            }
        }
        Value::Array(a) => {
            // A few elements of a long array are enough.
            for (i, x) in a.iter().enumerate().take(4) {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                pointers(x, &p, out);
            }
        }
        _ => {}
    }
}

/// Split a pointer into its parent and last segment (unescaped).
fn split(p: &str) -> (&str, String) {
    let i = p.rfind('/').unwrap_or(0);
    (&p[..i], p[i + 1..].replace("~1", "/").replace("~0", "~"))
}

/// Set `v` at pointer `p`, creating objects on the way (replacing what is not one).
fn set(root: &mut Value, p: &str, v: Value) {
    let mut cur = root;
    let segs: Vec<String> = p.split('/').skip(1).map(|s| s.replace("~1", "/").replace("~0", "~")).collect();
    for (i, s) in segs.iter().enumerate() {
        if let Value::Array(a) = cur {
            let n = a.len();
            let idx = s.parse::<usize>().unwrap_or(n).min(n.saturating_sub(1));
            if n == 0 {
                a.push(Value::Null);
            }
            cur = &mut a[idx];
        } else {
            if !cur.is_object() {
                *cur = Value::Object(Map::new());
            }
            let m = cur.as_object_mut().expect("an object");
            cur = m.entry(s.clone()).or_insert(Value::Null);
        }
        if i + 1 == segs.len() {
            *cur = v;
            return;
        }
    }
}

fn remove(root: &mut Value, p: &str) {
    let (parent, key) = split(p);
    match root.pointer_mut(parent) {
        Some(Value::Object(m)) => {
            m.remove(&key);
        }
        Some(Value::Array(a)) => {
            if let Ok(i) = key.parse::<usize>() {
                if i < a.len() {
                    a.remove(i);
                }
            }
        }
        _ => {}
    }
}

fn long_string(rng: &mut Rng) -> String {
    let unit = *rng.pick(&["x", "é", "流", "🫧", "\u{0}", "\\", "\"", "\u{10ffff}"]);
    unit.repeat(*rng.pick(&[199, 200, 201, 1000, 50_000]))
}

/// A value of a random kind.
fn any_value(rng: &mut Rng, depth: usize) -> Value {
    match rng.below(if depth > 2 { 6 } else { 8 }) {
        0 => Value::Null,
        1 => Value::Bool(rng.chance(0.5)),
        2 => json_f64(*rng.pick(NUMBERS)),
        3 => json!(rng.next_u64() >> rng.below(64)),
        4 => json!(-((rng.next_u64() >> (1 + rng.below(63))) as i64)),
        5 => Value::String(if rng.chance(0.1) { long_string(rng) } else { rng.pick(STRINGS).to_string() }),
        6 => Value::Array((0..rng.below(4)).map(|_| any_value(rng, depth + 1)).collect()),
        _ => {
            let mut m = Map::new();
            for _ in 0..rng.below(3) {
                m.insert(rng.pick(STRINGS).to_string(), any_value(rng, depth + 1));
            }
            Value::Object(m)
        }
    }
}

fn json_f64(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// A huge or odd array: positions (spread or all at one point), numbers or nested arrays.
fn huge_array(rng: &mut Rng) -> Value {
    let n = *rng.pick(&[0, 1, 2, 3, 100, 2_000, 6_000, 20_000]);
    match rng.below(5) {
        4 => Value::Array((0..n).map(|_| json!([0.0, 0.0, 0.01])).collect()),
        0 => Value::Array(
            (0..n).map(|i| json!([0.001 * (i % 7) as f64, 0.001 * (i % 5) as f64, 0.001 + 1e-5 * i as f64])).collect(),
        ),
        1 => Value::Array((0..n).map(|_| json_f64(*rng.pick(NUMBERS))).collect()),
        2 => Value::Array((0..n.min(2_000)).map(|_| json!([[1, 2, 3], [4]])).collect()),
        _ => Value::Array((0..n).map(|_| json!("voidage")).collect()),
    }
}

/// Change one place of the case.
fn mutate_value(v: &mut Value, rng: &mut Rng, label: &mut Vec<String>) {
    let mut ps = Vec::new();
    pointers(v, "", &mut ps);
    let p = if ps.is_empty() { "/name".to_string() } else { rng.pick(&ps).clone() };
    match rng.below(10) {
        0 => {
            remove(v, &p);
            label.push(format!("drop {p}"));
        }
        1 => {
            let x = any_value(rng, 0);
            label.push(format!("retype {p}"));
            set(v, &p, x);
        }
        2 => {
            let x = json_f64(*rng.pick(NUMBERS));
            label.push(format!("number {p}={x}"));
            set(v, &p, x);
        }
        3 => {
            // Scale a number by a power of ten, maybe negated.
            if let Some(x) = v.pointer(&p).and_then(Value::as_f64) {
                let k = rng.below(61) as i32 - 30;
                let s = if rng.chance(0.3) { -1.0 } else { 1.0 };
                let y = json_f64(s * x * 10f64.powi(k));
                label.push(format!("scale {p}={y}"));
                set(v, &p, y);
            }
        }
        4 => {
            let k = *rng.pick(KNOWN);
            let x = if k.ends_with("positions_m") || k.ends_with("velocities_m_s") {
                huge_array(rng)
            } else {
                any_value(rng, 0)
            };
            label.push(format!("add {k}"));
            set(v, k, x);
        }
        5 => {
            let key = if rng.chance(0.5) { rng.pick(STRINGS).to_string() } else { long_string(rng) };
            let (parent, _) = split(&p);
            let at = format!("{parent}/{}", key.replace('~', "~0").replace('/', "~1"));
            label.push(format!("unknown key under {parent}"));
            set(v, &at, any_value(rng, 0));
        }
        6 => {
            label.push(format!("huge array {p}"));
            set(v, &p, huge_array(rng));
        }
        7 => {
            let s = if rng.chance(0.5) { long_string(rng) } else { rng.pick(STRINGS).to_string() };
            label.push(format!("string {p}"));
            set(v, &p, Value::String(s));
        }
        8 => {
            // Another variant of an enum section.
            let (k, x) = match rng.below(4) {
                0 => ("/bed", json!({ "explicit": { "positions_m": huge_array(rng) } })),
                1 => ("/voidage", json!({ "method": rng.pick(STRINGS).to_string() })),
                2 => ("/bed", json!({ "generated": { "count": rng.next_u64() >> rng.below(64) } })),
                _ => (
                    "/particles/normal_damping",
                    json!({ rng.pick(&["restitution", "tsuji_alpha", "both"]).to_string(): json_f64(*rng.pick(NUMBERS)) }),
                ),
            };
            label.push(format!("variant {k}"));
            set(v, k, x);
        }
        _ => {
            // Value-level nesting within the parser's depth limit and beyond it.
            let depth = *rng.pick(&[10, 100, 127, 128, 129, 200]);
            let mut x = json!(1);
            for _ in 0..depth {
                x = if rng.chance(0.5) { json!([x]) } else { json!({ "a": x }) };
            }
            label.push(format!("nest {depth} at {p}"));
            set(v, &p, x);
        }
    }
}

/// Edits made while writing JSON text: a raw token in place of one value, or an object's
/// key given twice.
enum TextEdit {
    Raw(String, String),
    Duplicate(String),
}

/// JSON text of `v` with `edit` applied at its pointer.
fn write(v: &Value, at: &str, edit: &TextEdit, out: &mut String) {
    if let TextEdit::Raw(p, tok) = edit {
        if p == at {
            out.push_str(tok);
            return;
        }
    }
    match v {
        Value::Object(m) => {
            out.push('{');
            let mut first = true;
            for (k, x) in m {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                let times = if matches!(edit, TextEdit::Duplicate(d) if *d == p) { 2 } else { 1 };
                for _ in 0..times {
                    if !first {
                        out.push(',');
                    }
                    first = false;
                    out.push_str(&Value::String(k.clone()).to_string());
                    out.push(':');
                    write(x, &p, edit, out);
                }
            }
            out.push('}');
        }
        Value::Array(a) => {
            out.push('[');
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                write(x, &format!("{at}/{i}"), edit, out);
            }
            out.push(']');
        }
        _ => out.push_str(&v.to_string()),
    }
}

/// Deep nesting as text, beyond any value this side would build.
fn deep_text(rng: &mut Rng) -> String {
    let depth = *rng.pick(&[129, 1_000, 100_000]);
    let (open, close) = if rng.chance(0.5) { ("[", "]") } else { ("{\"a\":", "}") };
    let closed = rng.chance(0.7);
    format!("{}1{}", open.repeat(depth), if closed { close.repeat(depth) } else { String::new() })
}

/// The `i`-th submission of a run seeded by `seed`, made from one of `bases`.
pub fn submission(bases: &[Value], seed: u64, i: u64) -> Submission {
    let mut rng = Rng::new(seed ^ i.wrapping_mul(0xd134_2543_de82_ef95));
    let base = rng.pick(bases);
    let mut v = base.clone();
    let mut label = Vec::new();
    for _ in 0..1 + rng.below(3) {
        mutate_value(&mut v, &mut rng, &mut label);
    }
    let mut ps = Vec::new();
    pointers(&v, "", &mut ps);
    let text_kind = rng.below(100);
    let mut value = Some(v.clone());
    let mut body: Vec<u8> = if text_kind < 55 || ps.is_empty() {
        if rng.chance(0.5) {
            v.to_string().into_bytes()
        } else {
            serde_json::to_string_pretty(&v).unwrap_or_default().into_bytes()
        }
    } else if text_kind < 70 {
        let p = rng.pick(&ps).clone();
        let tok = if rng.chance(0.2) { deep_text(&mut rng) } else { rng.pick(TOKENS).to_string() };
        label.push(format!("token {p}={}", tok.chars().take(24).collect::<String>()));
        value = None;
        let mut out = String::new();
        write(&v, "", &TextEdit::Raw(p, tok), &mut out);
        out.into_bytes()
    } else if text_kind < 78 {
        let p = rng.pick(&ps).clone();
        label.push(format!("duplicate {p}"));
        value = None;
        let mut out = String::new();
        write(&v, "", &TextEdit::Duplicate(p), &mut out);
        out.into_bytes()
    } else if text_kind < 88 {
        let t = v.to_string().into_bytes();
        let cut = rng.below(t.len().max(1));
        label.push(format!("truncate at {cut}"));
        value = None;
        t[..cut].to_vec()
    } else if text_kind < 95 {
        value = None;
        odd_body(&v, &mut rng, &mut label)
    } else {
        // Over the test servers' 256 KiB limit.
        let n = *rng.pick(&[300 << 10, 1 << 20, 3 << 20]);
        label.push(format!("huge body {n}"));
        value = None;
        let mut t = v.to_string().into_bytes();
        t.pop();
        t.extend_from_slice(b",\"name\":\"");
        t.resize(n, b'x');
        t.extend_from_slice(b"\"}");
        t
    };
    let content_type = if rng.chance(0.1) {
        let ct = *rng.pick(CONTENT_TYPES);
        label.push(format!("content-type {ct:?}"));
        ct
    } else {
        Some("application/json")
    };
    if body.is_empty() && value.is_some() {
        body = b"{}".to_vec();
    }
    // A body that is still JSON (a top-level scalar, an array of cases) is judged as such.
    if value.is_none() && body.len() < 1 << 20 {
        value = serde_json::from_slice(&body).ok();
    }
    Submission { body, content_type, label: label.join("; "), value }
}

/// Bodies that are not a case document at all.
fn odd_body(v: &Value, rng: &mut Rng, label: &mut Vec<String>) -> Vec<u8> {
    let text = v.to_string();
    let (what, body): (&str, Vec<u8>) = match rng.below(12) {
        0 => ("empty", Vec::new()),
        1 => ("whitespace", b" \n\t ".to_vec()),
        2 => ("bom", [b"\xef\xbb\xbf".as_slice(), text.as_bytes()].concat()),
        3 => ("trailing garbage", format!("{text} x").into_bytes()),
        4 => ("two documents", format!("{text}{text}").into_bytes()),
        5 => ("top-level scalar", rng.pick(&["null", "[]", "123", "\"case\"", "true", "[{}]"]).as_bytes().to_vec()),
        6 => ("utf-16", text.encode_utf16().flat_map(u16::to_le_bytes).collect()),
        7 => {
            let mut b = text.into_bytes();
            let at = rng.below(b.len().max(1));
            b.insert(at.min(b.len()), 0xff);
            ("invalid utf-8", b)
        }
        8 => ("latin-1 name", [b"{\"name\":\"caf\xe9\",".as_slice(), &text.as_bytes()[1..]].concat()),
        9 => ("nul bytes", text.replace(' ', "\0").into_bytes()),
        10 => ("deep text", deep_text(rng).into_bytes()),
        _ => ("array of cases", format!("[{text},{text}]").into_bytes()),
    };
    label.push(what.into());
    body
}
