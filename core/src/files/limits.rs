//! The one set of limits every reader counts against: a mesh file of any format, a glTF scene and
//! a scene file. A count past its limit is refused, naming the limit, before what it counts is
//! made; every reader also bounds what it allocates by the file's size (a header's count never
//! reserves more than the file could hold), so these are the ceiling on a file that is as large
//! as it claims.

/// A count a file may not exceed, with what it counts in words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limit {
    /// What is counted, plural ("triangles").
    pub what: &'static str,
    pub max: u64,
}

/// Triangles one file may give: what one BVH level is built over here (`MAX_FLAT_TRIANGLES`),
/// about 26 bytes each in the mesh and 100 more while a build runs.
pub const TRIANGLES: Limit = Limit { what: "triangles", max: 20_000_000 };

/// Vertices one file may give: three a triangle (STL, unindexed glTF) at the triangle limit.
pub const VERTICES: Limit = Limit { what: "vertices", max: 3 * TRIANGLES.max };

/// Placements (instances of a mesh) one scene may make, a scene file or a glTF's nodes. Each costs
/// some 900 bytes while a scene file is read (a JSON object, a placement with its path and
/// transform): three million took 2.6 GB and 17 s, a quarter of a million stays near 200 MB. More
/// instances than that are a program's to make (`TwoLevelBvh`), not a file's to list.
pub const PLACEMENTS: Limit = Limit { what: "placements", max: 250_000 };

/// Nodes of a glTF's hierarchy (each visited once: the hierarchy is a forest).
pub const NODES: Limit = Limit { what: "nodes", max: 1_000_000 };

/// The bytes of buffers one glTF may read (a GLB's binary chunk, data URIs, files beside it):
/// more than the largest mesh the other limits allow, with its normals, texture coordinates and
/// a few textures.
pub const BUFFER_BYTES: Limit = Limit { what: "bytes of buffers", max: 2 << 30 };

/// Bytes of mesh data (12 a vertex, 12 a triangle) a file may make for each byte it holds, counting
/// its buffers. A valid file makes about one to four (a vertex read once, a triangle from 3 to 12
/// bytes of indices); one that names the same data again and again (an accessor named by 500
/// primitives, many accessors over one view) makes more, and is refused past this.
pub const MADE_PER_BYTE: u64 = 8;

/// What any file may make past `MADE_PER_BYTE` times its size (a small file's shared accessors).
pub const MADE_SLACK: u64 = 1 << 20;

impl Limit {
    /// `Ok` when `n` is within the limit, else the refusal in words ("30000000 triangles, more
    /// than the 20000000 bvhscope reads from one file").
    pub fn check(&self, n: u64) -> Result<(), String> {
        if n <= self.max {
            return Ok(());
        }
        Err(format!("{n} {}, more than the {} bvhscope reads from one file", self.what, self.max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_past_its_limit_is_refused_naming_it() {
        assert!(TRIANGLES.check(TRIANGLES.max).is_ok());
        let e = PLACEMENTS.check(PLACEMENTS.max + 1).unwrap_err();
        assert_eq!(e, "250001 placements, more than the 250000 bvhscope reads from one file");
    }
}
