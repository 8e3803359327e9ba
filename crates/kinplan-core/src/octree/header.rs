//! The text header of OctoMap's `.bt` and `.ot` files, read and written.

use super::OctreeError;

/// First line of a `.bt` file.
pub const BT_FIRST_LINE: &str = "# Octomap OcTree binary file";
/// First line of a `.ot` file.
pub const OT_FIRST_LINE: &str = "# Octomap OcTree file";
const COMMENT: &str = "# (feel free to add / change comments, but leave the first line as it is!)\n#\n";
/// Longest header scanned before the `data` line (bytes).
const MAX_HEADER: usize = 64 * 1024;

/// What a header declares.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header {
    pub id: String,
    pub size: u64,
    pub resolution: f64,
    /// Byte offset of the first node byte.
    pub data_offset: usize,
}

/// Parses the header as OctoMap's `readBinaryFileHeader` / `readHeader` do: the first
/// line must start with `first_line`; then lines of `#` comments, `id T`, `size N`,
/// `res R`, unknown keywords skipped, up to the line `data`.
pub(crate) fn parse_header(bytes: &[u8], first_line: &str) -> Result<Header, OctreeError> {
    let bad = |offset: usize, reason: &str| OctreeError::BadHeader {
        offset,
        reason: reason.to_string(),
    };
    if !bytes.starts_with(first_line.as_bytes()) {
        return Err(bad(0, &format!("first line is not '{first_line}'")));
    }
    let (mut id, mut size, mut res) = (None::<String>, None::<u64>, None::<f64>);
    let mut pos = 0usize;
    loop {
        if pos >= bytes.len() || pos > MAX_HEADER {
            return Err(bad(pos.min(bytes.len()), "no 'data' line"));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map(|e| pos + e)
            .ok_or_else(|| bad(pos, "no 'data' line"))?;
        let line = std::str::from_utf8(&bytes[pos..end]).map_err(|_| bad(pos, "header line is not text"))?;
        let line_start = pos;
        pos = end + 1;
        if line_start == 0 {
            continue;
        }
        let mut tokens = line.split_ascii_whitespace();
        let Some(word) = tokens.next() else { continue };
        if word.starts_with('#') {
            continue;
        }
        let value = tokens.next();
        match word {
            "data" => break,
            "id" => {
                id = Some(
                    value
                        .ok_or_else(|| bad(line_start, "'id' without a value"))?
                        .to_string(),
                )
            }
            "size" => {
                size = Some(
                    value
                        .and_then(|v| v.parse::<u64>().ok())
                        .ok_or_else(|| bad(line_start, "'size' is not a non-negative integer"))?,
                )
            }
            "res" => {
                let r = value
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or_else(|| bad(line_start, "'res' is not a number"))?;
                if !(r.is_finite() && r > 0.0) {
                    return Err(OctreeError::BadResolution(r));
                }
                res = Some(r)
            }
            _ => {}
        }
    }
    Ok(Header {
        id: id.unwrap_or_else(|| "OcTree".to_string()),
        size: size.ok_or_else(|| bad(pos, "no 'size' line"))?,
        resolution: res.ok_or_else(|| bad(pos, "no 'res' line"))?,
        data_offset: pos,
    })
}

/// Writes the header OctoMap writes (`writeBinaryConst` / `AbstractOcTree::write`).
pub(crate) fn write_header(out: &mut Vec<u8>, first_line: &str, size: usize, resolution: f64) {
    out.extend_from_slice(first_line.as_bytes());
    out.push(b'\n');
    out.extend_from_slice(COMMENT.as_bytes());
    out.extend_from_slice(
        format!("id OcTree\nsize {size}\nres {}\ndata\n", format_g6(resolution)).as_bytes(),
    );
}

/// A double as C++ `ostream << x` prints it by default (`%g`, 6 significant digits).
pub(crate) fn format_g6(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let sci = format!("{x:.5e}");
    let (mant, exp) = sci.split_once('e').expect("exponent form");
    let exp: i32 = exp.parse().expect("integer exponent");
    let strip = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if !(-4..6).contains(&exp) {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", strip(mant), exp.abs())
    } else {
        let decimals = (5 - exp).max(0) as usize;
        strip(&format!("{x:.decimals$}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g6_matches_printf() {
        // values printf("%g") gives for these doubles
        assert_eq!(format_g6(0.08), "0.08");
        assert_eq!(format_g6(0.1), "0.1");
        assert_eq!(format_g6(0.075), "0.075");
        assert_eq!(format_g6(1.0), "1");
        assert_eq!(format_g6(0.123456789), "0.123457");
        assert_eq!(format_g6(0.00001), "1e-05");
        assert_eq!(format_g6(1234567.0), "1.23457e+06");
        assert_eq!(format_g6(100000.0), "100000");
    }

    #[test]
    fn header_fields_and_errors() {
        let h = b"# Octomap OcTree binary file\n# c\nid OcTree\nfoo bar\nsize 3\nres 0.05\ndata\nXY";
        let p = parse_header(h, BT_FIRST_LINE).unwrap();
        assert_eq!((p.id.as_str(), p.size, p.resolution), ("OcTree", 3, 0.05));
        assert_eq!(&h[p.data_offset..], b"XY");
        assert!(matches!(
            parse_header(b"# Octomap", BT_FIRST_LINE),
            Err(OctreeError::BadHeader { offset: 0, .. })
        ));
        let e = parse_header(
            b"# Octomap OcTree binary file\nsize -3\nres 1\ndata\n",
            BT_FIRST_LINE,
        );
        assert!(
            matches!(e, Err(OctreeError::BadHeader { offset: 29, .. })),
            "{e:?}"
        );
        let e = parse_header(
            b"# Octomap OcTree binary file\nsize 3\nres nan\ndata\n",
            BT_FIRST_LINE,
        );
        assert!(matches!(e, Err(OctreeError::BadResolution(_))));
        let e = parse_header(b"# Octomap OcTree binary file\nsize 3\nres 0.1\n", BT_FIRST_LINE);
        assert!(matches!(e, Err(OctreeError::BadHeader { .. })));
    }
}
