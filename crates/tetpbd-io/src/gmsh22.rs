//! The `$Nodes` and `$Elements` sections of Gmsh `.msh` format 2.2 ASCII.
//!
//! `$Nodes`: a count, then one row per node `<tag> <x> <y> <z>`. `$Elements`: a count, then
//! one row per element `<tag> <type> <number of tags> <tags…> <node tags…>`; only type 4
//! (4-node tetrahedron) is kept. The surrounding file is read by [`crate::gmsh`].

use std::collections::HashMap;

use nalgebra::Vector3;

use crate::error::{FileKind, ReadError};
use crate::gmsh::{data_row, end_section, NodeTable, TETRAHEDRON};
use crate::text::{capacity_hint, Rows};

/// The count row opening a 2.2 section.
fn count_row(rows: &mut Rows<'_>, what: &'static str) -> Result<u64, ReadError> {
    let (line, fields) = data_row(rows, what, 1, 0)?;
    if fields.len() != 1 {
        return Err(rows.field_count(line, what, 1, fields.len()));
    }
    rows.uint(line, what, fields[0])
}

/// Reads the rows of a 2.2 `$Nodes` section after its `$Nodes` line, through `$EndNodes`.
pub(crate) fn read_nodes(rows: &mut Rows<'_>, text: &str) -> Result<NodeTable, ReadError> {
    let count = count_row(rows, "number of nodes")?;
    let mut vertices = Vec::with_capacity(capacity_hint(count, text, 8));
    let mut tags = HashMap::with_capacity(capacity_hint(count, text, 8));
    for n in 0..count {
        let (line, fields) = data_row(rows, "node rows", count, n)?;
        if fields.len() != 4 {
            return Err(rows.field_count(line, "node row", 4, fields.len()));
        }
        let tag = rows.uint(line, "node tag", fields[0])?;
        let x = rows.coord(line, "x coordinate", fields[1])?;
        let y = rows.coord(line, "y coordinate", fields[2])?;
        let z = rows.coord(line, "z coordinate", fields[3])?;
        let index = u32::try_from(n).map_err(|_| ReadError::Unsupported {
            kind: FileKind::Msh,
            line,
            what: "more than 2^32 nodes".to_string(),
        })?;
        if tags.insert(tag, index).is_some() {
            return Err(ReadError::DuplicateTag {
                kind: FileKind::Msh,
                line,
                tag,
            });
        }
        vertices.push(Vector3::new(x, y, z));
    }
    end_section(rows, "$EndNodes")?;
    Ok((vertices, tags))
}

/// Reads the rows of a 2.2 `$Elements` section after its `$Elements` line, through
/// `$EndElements`, keeping the tetrahedra.
pub(crate) fn read_elements(
    rows: &mut Rows<'_>,
    text: &str,
    tags: &HashMap<u64, u32>,
    vertex_count: usize,
) -> Result<Vec<[u32; 4]>, ReadError> {
    let count = count_row(rows, "number of elements")?;
    let mut tets = Vec::with_capacity(capacity_hint(count, text, 8));
    for n in 0..count {
        let (line, fields) = data_row(rows, "element rows", count, n)?;
        if fields.len() < 3 {
            return Err(rows.field_count(line, "element row", 3, fields.len()));
        }
        rows.uint(line, "element tag", fields[0])?;
        let element_type = rows.int(line, "element type", fields[1])?;
        let tag_count = rows.uint(line, "number of tags", fields[2])?;
        for t in fields
            .iter()
            .skip(3)
            .take(tag_count.min(fields.len() as u64) as usize)
        {
            rows.int(line, "element tag value", t)?;
        }
        if element_type != TETRAHEDRON {
            continue;
        }
        let width = usize::try_from(tag_count)
            .ok()
            .and_then(|t| t.checked_add(7))
            .filter(|&w| w == fields.len())
            .ok_or_else(|| {
                let expected =
                    usize::try_from(tag_count).map_or(usize::MAX, |t| t.saturating_add(7));
                rows.field_count(line, "tetrahedron row", expected, fields.len())
            })?;
        let mut tet = [0u32; 4];
        for (slot, text) in tet.iter_mut().zip(&fields[width - 4..]) {
            let tag = rows.uint(line, "node tag", text)?;
            *slot = *tags.get(&tag).ok_or(ReadError::IndexOutOfRange {
                kind: FileKind::Msh,
                line,
                index: tag,
                vertex_count,
            })?;
        }
        tets.push(tet);
    }
    end_section(rows, "$EndElements")?;
    Ok(tets)
}
