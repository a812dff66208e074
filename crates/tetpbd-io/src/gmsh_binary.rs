//! Gmsh `.msh` files, format 4.1 binary.
//!
//! The layout is that of the ASCII format with the numbers of `$Nodes` and `$Elements`
//! stored as raw values: `int` is 4 bytes, `size_t` is the file's data size (8), coordinates
//! are 8-byte doubles, all in the byte order given by the `1` stored in `$MeshFormat`. Other
//! sections are skipped up to their `$End…` line. Errors inside binary data are
//! [`ReadError::Binary`] with a byte offset.

use std::collections::HashMap;

use nalgebra::Vector3;
use tetpbd::TetMesh;

use crate::error::{FileKind, ReadError};
use crate::gmsh::{NodeTable, TETRAHEDRON};

/// Number of nodes of a Gmsh element type (`None` for types this reader does not know).
fn nodes_per_element(element_type: i32) -> Option<u64> {
    Some(match element_type {
        15 => 1,
        1 => 2,
        2 | 8 => 3,
        3 | 4 | 26 => 4,
        7 | 27 => 5,
        6 | 9 | 28 => 6,
        5 | 16 => 8,
        10 | 20 => 9,
        11 | 21 => 10,
        22 => 12,
        19 => 13,
        14 => 14,
        18 | 23 | 24 => 15,
        13 => 18,
        17 | 29 => 20,
        25 => 21,
        12 => 27,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// A reading position in the bytes of a binary file.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// True when the file's byte order is big-endian.
    big_endian: bool,
}

impl<'a> Cursor<'a> {
    fn error(&self, what: impl Into<String>) -> ReadError {
        ReadError::Binary {
            kind: FileKind::Msh,
            offset: self.pos,
            what: what.into(),
        }
    }

    /// The next line without its `\n` (and a trailing `\r`); `None` at the end.
    fn line(&mut self) -> Option<&'a [u8]> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (len + 1).min(rest.len());
        let line = &rest[..len];
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    }

    /// The next non-blank line, trimmed.
    fn text_line(&mut self) -> Option<&'a [u8]> {
        while let Some(line) = self.line() {
            let trimmed = line.trim_ascii();
            if !trimmed.is_empty() {
                return Some(trimmed);
            }
        }
        None
    }

    /// Fails unless the next non-blank line is `expected`.
    fn expect_line(&mut self, expected: &str) -> Result<(), ReadError> {
        let start = self.pos;
        match self.text_line() {
            Some(line) if line == expected.as_bytes() => Ok(()),
            _ => {
                self.pos = start;
                Err(self.error(format!("expected `{expected}`")))
            }
        }
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ReadError> {
        let bytes = self
            .bytes
            .get(self.pos..self.pos.saturating_add(N))
            .ok_or_else(|| self.error(format!("input ends inside {what}")))?;
        self.pos += N;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        if self.big_endian {
            out.reverse();
        }
        Ok(out)
    }

    fn int(&mut self, what: &str) -> Result<i32, ReadError> {
        Ok(i32::from_le_bytes(self.take(what)?))
    }

    fn size(&mut self, what: &str) -> Result<u64, ReadError> {
        Ok(u64::from_le_bytes(self.take(what)?))
    }

    fn coord(&mut self, what: &str) -> Result<f32, ReadError> {
        let v = f64::from_le_bytes(self.take(what)?) as f32;
        if v.is_finite() {
            Ok(v)
        } else {
            self.pos -= 8;
            Err(self.error(format!("{what} is not finite")))
        }
    }

    /// Fails unless `count` items of `item_bytes` bytes remain.
    fn ensure(&self, count: u64, item_bytes: u64, what: &str) -> Result<(), ReadError> {
        let need = count.checked_mul(item_bytes);
        let left = (self.bytes.len() - self.pos.min(self.bytes.len())) as u64;
        match need {
            Some(n) if n <= left => Ok(()),
            _ => Err(self.error(format!("input ends before {count} {what}"))),
        }
    }
}

/// Reads a mesh from the bytes of a `.msh` 4.1 binary file.
pub(crate) fn read_binary(bytes: &[u8]) -> Result<TetMesh, ReadError> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        big_endian: false,
    };
    c.expect_line("$MeshFormat")?;
    let start = c.pos;
    let format = c.text_line().unwrap_or_default();
    if !format
        .split(u8::is_ascii_whitespace)
        .filter(|f| !f.is_empty())
        .eq([&b"4.1"[..], b"1", b"8"])
    {
        c.pos = start;
        return Err(c.error("expected `4.1 1 8` (version 4.1, binary, 8-byte size_t)"));
    }
    let one: [u8; 4] = c.take("the byte-order marker")?;
    c.big_endian = match one {
        [1, 0, 0, 0] => false,
        [0, 0, 0, 1] => true,
        _ => {
            c.pos -= 4;
            return Err(c.error("byte-order marker is not the integer 1"));
        }
    };
    c.expect_line("$EndMeshFormat")?;
    let mut nodes: Option<NodeTable> = None;
    let mut tets = None;
    while let Some(name) = c.text_line() {
        match name {
            b"$Nodes" if nodes.is_none() => {
                nodes = Some(read_nodes(&mut c)?);
                c.expect_line("$EndNodes")?;
            }
            b"$Elements" if tets.is_none() => {
                let Some((_, tags)) = &nodes else {
                    return Err(c.error("$Elements before $Nodes"));
                };
                tets = Some(read_elements(&mut c, tags)?);
                c.expect_line("$EndElements")?;
            }
            b"$Nodes" | b"$Elements" => return Err(c.error("a repeated section")),
            _ if name.first() == Some(&b'$') => {
                let mut end = b"$End".to_vec();
                end.extend_from_slice(&name[1..]);
                loop {
                    match c.text_line() {
                        Some(line) if line == end.as_slice() => break,
                        Some(_) => {}
                        None => return Err(c.error("a skipped section is not closed")),
                    }
                }
            }
            _ => return Err(c.error("text outside a section")),
        }
    }
    let (Some((vertices, _)), Some(tets)) = (nodes, tets) else {
        return Err(c.error("missing $Nodes or $Elements"));
    };
    Ok(TetMesh { vertices, tets })
}

fn read_nodes(c: &mut Cursor<'_>) -> Result<NodeTable, ReadError> {
    let blocks = c.size("the $Nodes header")?;
    let total = c.size("the $Nodes header")?;
    c.size("the $Nodes header")?;
    c.size("the $Nodes header")?;
    let mut vertices = Vec::new();
    let mut tags = HashMap::new();
    let mut sum = 0u64;
    for _ in 0..blocks {
        let dim = c.int("a node block header")?;
        c.int("a node block header")?;
        let parametric = c.int("a node block header")?;
        let count = c.size("a node block header")?;
        if !(0..=3).contains(&dim) || !(0..=1).contains(&parametric) {
            return Err(c.error(format!(
                "node block with entityDim {dim}, parametric {parametric}"
            )));
        }
        let width = 3 + if parametric == 1 { dim as u64 } else { 0 };
        c.ensure(count, 8 + 8 * width, "nodes")?;
        for _ in 0..count {
            let tag = c.size("node tags")?;
            let index = u32::try_from(tags.len()).map_err(|_| c.error("more than 2^32 nodes"))?;
            if tags.insert(tag, index).is_some() {
                c.pos -= 8;
                return Err(c.error(format!("node tag {tag} defined twice")));
            }
        }
        for _ in 0..count {
            let x = c.coord("x coordinate")?;
            let y = c.coord("y coordinate")?;
            let z = c.coord("z coordinate")?;
            for _ in 3..width {
                c.coord("parametric coordinate")?;
            }
            vertices.push(Vector3::new(x, y, z));
        }
        sum = sum.saturating_add(count);
    }
    if sum != total {
        return Err(c.error(format!(
            "$Nodes header announces {total} nodes, the blocks hold {sum}"
        )));
    }
    Ok((vertices, tags))
}

fn read_elements(c: &mut Cursor<'_>, tags: &HashMap<u64, u32>) -> Result<Vec<[u32; 4]>, ReadError> {
    let blocks = c.size("the $Elements header")?;
    let total = c.size("the $Elements header")?;
    c.size("the $Elements header")?;
    c.size("the $Elements header")?;
    let mut tets = Vec::new();
    let mut sum = 0u64;
    for _ in 0..blocks {
        c.int("an element block header")?;
        c.int("an element block header")?;
        let element_type = c.int("an element block header")?;
        let count = c.size("an element block header")?;
        let Some(per) = nodes_per_element(element_type) else {
            c.pos -= 12;
            return Err(c.error(format!("unknown element type {element_type}")));
        };
        c.ensure(count, 8 * (1 + per), "elements")?;
        for _ in 0..count {
            c.size("element tags")?;
            if i64::from(element_type) != TETRAHEDRON {
                for _ in 0..per {
                    c.size("element nodes")?;
                }
                continue;
            }
            let mut tet = [0u32; 4];
            for slot in &mut tet {
                let tag = c.size("element nodes")?;
                *slot = *tags.get(&tag).ok_or_else(|| {
                    c.error(format!(
                        "node tag {tag} does not exist ({} nodes)",
                        tags.len()
                    ))
                })?;
            }
            tets.push(tet);
        }
        sum = sum.saturating_add(count);
    }
    if sum != total {
        return Err(c.error(format!(
            "$Elements header announces {total} elements, the blocks hold {sum}"
        )));
    }
    Ok(tets)
}
