//! tobj's single index, as the parallel reader (`obj_parallel.rs`) makes it: each distinct
//! `v/vt/vn` corner of a model numbered in order of first use, its attributes in that order.
//!
//! Big models are numbered in parallel (issue 37: on one thread this was a tenth of loading a
//! 4M-triangle file, and all of it serial): the first corner to use each position is found with
//! an atomic minimum; a corner whose key is that first corner's is numbered as it; the rest (seams,
//! creases) are grouped by key with a sort; a corner is a first use when it is its own group's
//! first, and prefix sums over those flags give the numbers. Every step's result is a minimum, a
//! sort or a sum, so the numbers are the serial ones on any thread count (a test compares them).

use crate::parallel::{exclusive_scan, region};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, Ordering};

/// An absent texture or normal index.
pub(super) const MISSING: u32 = u32::MAX;
/// Floats per position, texture coordinate and normal, the three attributes a corner names.
pub(super) const WIDTH: [usize; 3] = [3, 2, 3];

/// Models with at least this many corners are numbered in parallel; smaller ones on the calling
/// thread (a file of 50,000 small objects must not pay the pool 50,000 times).
const PARALLEL_CORNERS: usize = 1 << 16;

/// Numbers each distinct corner of a model in order of first use, as tobj's single index does.
/// Most corners name a position whose first corner already has the same texture coordinate and
/// normal, so a table by position answers them; only a position met with different ones (a seam,
/// a crease) needs the hash map.
pub(super) struct Numbering {
    by_position: Vec<u32>,
    others: HashMap<[u32; 3], u32>,
}

impl Numbering {
    pub(super) fn new(positions: usize) -> Numbering {
        Numbering { by_position: vec![MISSING; positions], others: HashMap::new() }
    }

    pub(super) fn mesh(&mut self, attrs: &[Vec<f32>; 3], corners: &[[u32; 3]]) -> tobj::Mesh {
        if corners.len() >= PARALLEL_CORNERS {
            region(|| numbered_in_parallel(attrs, corners, self.by_position.len()))
        } else {
            self.serial(attrs, corners)
        }
    }

    /// One corner after the other.
    fn serial(&mut self, attrs: &[Vec<f32>; 3], corners: &[[u32; 3]]) -> tobj::Mesh {
        let mut mesh = tobj::Mesh::default();
        let mut keys: Vec<[u32; 3]> = Vec::new();
        mesh.indices.reserve(corners.len());
        for &key in corners {
            let first = self.by_position[key[0] as usize];
            let index = if first != MISSING && keys[first as usize] == key {
                first
            } else {
                let next = keys.len() as u32;
                let index = if first == MISSING {
                    self.by_position[key[0] as usize] = next;
                    next
                } else {
                    *self.others.entry(key).or_insert(next)
                };
                if index == next {
                    keys.push(key);
                    push_attributes(&mut mesh, attrs, key);
                }
                index
            };
            mesh.indices.push(index);
        }
        // Ready for the next model.
        for k in &keys {
            self.by_position[k[0] as usize] = MISSING;
        }
        // A fresh map, not `clear()`: clearing costs the map's capacity, which one big object with
        // many seams would leave behind for every small object after it.
        self.others = HashMap::new();
        mesh
    }
}

/// The attributes a corner's key names, appended.
fn push_attributes(mesh: &mut tobj::Mesh, attrs: &[Vec<f32>; 3], key: [u32; 3]) {
    let [v, vt, vn] = key.map(|i| i as usize);
    mesh.positions.extend_from_slice(&attrs[0][3 * v..3 * v + 3]);
    if vt != MISSING as usize {
        mesh.texcoords.extend_from_slice(&attrs[1][2 * vt..2 * vt + 2]);
    }
    if vn != MISSING as usize {
        mesh.normals.extend_from_slice(&attrs[2][3 * vn..3 * vn + 3]);
    }
}

/// `Numbering::mesh` for a big model, in parallel (the module's comment says how).
fn numbered_in_parallel(attrs: &[Vec<f32>; 3], corners: &[[u32; 3]], positions: usize) -> tobj::Mesh {
    let first: Vec<AtomicU32> = (0..positions).into_par_iter().map(|_| AtomicU32::new(MISSING)).collect();
    corners.par_iter().enumerate().for_each(|(c, k)| {
        first[k[0] as usize].fetch_min(c as u32, Ordering::Relaxed);
    });
    // Each corner's representative: the first corner with its key (MISSING: not known yet).
    let mut rep: Vec<u32> = corners
        .par_iter()
        .map(|k| {
            let f = first[k[0] as usize].load(Ordering::Relaxed);
            if corners[f as usize] == *k {
                f
            } else {
                MISSING
            }
        })
        .collect();
    drop(first);
    // The others, grouped by key in corner order: each group's first is its representative.
    let mut odd: Vec<([u32; 3], u32)> =
        rep.par_iter().enumerate().filter(|(_, &r)| r == MISSING).map(|(c, _)| (corners[c], c as u32)).collect();
    odd.par_sort_unstable();
    for group in odd.chunk_by(|a, b| a.0 == b.0) {
        for &(_, c) in group {
            rep[c as usize] = group[0].1;
        }
    }
    // A corner is a first use when it is its own representative; the number of a first use is
    // how many come before it.
    let mut number: Vec<u32> = rep.par_iter().enumerate().map(|(c, &r)| (r == c as u32) as u32).collect();
    let distinct = exclusive_scan(&mut number) as usize;
    let firsts: Vec<u32> = rep.par_iter().enumerate().filter(|(c, &r)| r == *c as u32).map(|(c, _)| c as u32).collect();
    debug_assert_eq!(firsts.len(), distinct);
    let indices: Vec<u32> = rep.par_iter().map(|&r| number[r as usize]).collect();
    let of = |a: usize, c: u32| corners[c as usize][a] as usize;
    let positions: Vec<[f32; 3]> =
        firsts.par_iter().map(|&c| std::array::from_fn(|i| attrs[0][WIDTH[0] * of(0, c) + i])).collect();
    // A file's corners all have one form, so either every first use names a texture coordinate
    // (normal) or none does.
    let has = |a: usize| firsts.first().is_some_and(|&c| of(a, c) != MISSING as usize);
    let texcoords: Vec<[f32; 2]> = if has(1) {
        firsts.par_iter().map(|&c| std::array::from_fn(|i| attrs[1][WIDTH[1] * of(1, c) + i])).collect()
    } else {
        Vec::new()
    };
    let normals: Vec<[f32; 3]> = if has(2) {
        firsts.par_iter().map(|&c| std::array::from_fn(|i| attrs[2][WIDTH[2] * of(2, c) + i])).collect()
    } else {
        Vec::new()
    };
    tobj::Mesh {
        positions: positions.into_flattened(),
        texcoords: texcoords.into_flattened(),
        normals: normals.into_flattened(),
        indices,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel numbering is the serial one: the same indices and attributes, on corners
    /// with seams (a position met with several texture coordinates and normals), on one thread
    /// and on four.
    #[test]
    fn the_parallel_numbering_is_the_serial_one() {
        let mut rng = crate::random::Rng::new(11);
        let (positions, uvs, normals) = (30_000u32, 500u32, 40u32);
        let attrs = [
            (0..3 * positions).map(|i| i as f32).collect::<Vec<f32>>(),
            (0..2 * uvs).map(|i| -(i as f32)).collect(),
            (0..3 * normals).map(|i| i as f32 * 0.5).collect(),
        ];
        let corners: Vec<[u32; 3]> = (0..PARALLEL_CORNERS as u32 + 999)
            .map(|_| {
                let v = rng.below(positions as u64) as u32;
                // Most positions keep one uv and normal; one in eight corners is a seam.
                let seam = rng.below(8) == 0;
                let (vt, vn) = if seam { (rng.below(3) as u32, rng.below(2) as u32) } else { (v % uvs, v % normals) };
                [v, vt, vn]
            })
            .collect();
        let serial = Numbering::new(positions as usize).serial(&attrs, &corners);
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let par = pool.install(|| Numbering::new(positions as usize).mesh(&attrs, &corners));
            assert_eq!(par.indices, serial.indices, "{threads} threads: indices");
            assert_eq!(par.positions, serial.positions, "{threads} threads: positions");
            assert_eq!(par.texcoords, serial.texcoords, "{threads} threads: texcoords");
            assert_eq!(par.normals, serial.normals, "{threads} threads: normals");
        }
    }
}
