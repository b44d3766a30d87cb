//! A glTF accessor's elements, read by us from the buffers with every count, offset, stride, type
//! and sparse index checked first: the gltf crate's own reader asserts (a `byteStride` smaller
//! than the element) or reaches `unreachable!` (float indices) on such files, and a panic from a
//! user's file is a bug. What is read counts against a budget in proportion to the file's bytes
//! (`files::limits::MADE_PER_BYTE`), so data named again and again is refused, not multiplied.
//! Accessors, views and sparse storage as the glTF 2.0 specification (§3.6) lays them out.

use crate::files::limits::{self, MADE_PER_BYTE, MADE_SLACK};
use glam::Vec3;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;

/// The buffers' bytes and what reading them has made so far.
pub(super) struct Access<'a> {
    pub root: &'a gltf::json::Root,
    pub buffers: Vec<Vec<u8>>,
    made: u64,
    budget: u64,
}

/// Why an accessor cannot be read: the words that follow "accessor N" in the error.
type Why = String;

/// What the elements of an accessor must be for the use it is put to.
#[derive(Clone, Copy)]
enum Want {
    /// POSITION or NORMAL: three floats.
    Vec3,
    /// A primitive's indices: one unsigned integer.
    Index,
}

fn size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn read_u32(b: &[u8], c: ComponentType) -> u32 {
    match c {
        ComponentType::U8 => b[0] as u32,
        ComponentType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

impl<'a> Access<'a> {
    /// `file_bytes`: the size of the glTF or GLB file itself; the buffers' sizes are added.
    pub fn new(root: &'a gltf::json::Root, buffers: Vec<Vec<u8>>, file_bytes: u64) -> Access<'a> {
        let total = file_bytes + buffers.iter().map(|b| b.len() as u64).sum::<u64>();
        Access { root, buffers, made: 0, budget: total.saturating_mul(MADE_PER_BYTE).saturating_add(MADE_SLACK) }
    }

    /// Count `bytes` of mesh data made against the budget.
    pub fn make(&mut self, bytes: u64) -> Result<(), Why> {
        self.made = self.made.saturating_add(bytes);
        if self.made > self.budget {
            return Err(format!(
                "the file makes more than {} bytes of mesh data from its {} bytes (its data is named again and again); refused",
                self.budget,
                (self.budget - MADE_SLACK) / MADE_PER_BYTE
            ));
        }
        Ok(())
    }

    /// Accessor `index` as positions or normals (three floats each).
    pub fn vec3s(&mut self, index: usize) -> Result<Vec<Vec3>, Why> {
        let flat = self.elements(index, Want::Vec3)?;
        Ok(flat.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
    }

    /// Accessor `index` as a primitive's indices.
    pub fn indices(&mut self, index: usize) -> Result<Vec<u32>, Why> {
        let (c, count) = self.check(index, Want::Index)?;
        let a = &self.root.accessors[index];
        let mut out = vec![0u32; count];
        if let Some(v) = a.buffer_view {
            let (bytes, stride) = self.view_bytes(v.value(), a.byte_offset.map_or(0, |o| o.0), count, size(c))?;
            for (k, o) in out.iter_mut().enumerate() {
                *o = read_u32(&bytes[k * stride..], c);
            }
        }
        if let Some(s) = &a.sparse {
            let (at, values) = self.sparse(s, count, size(c))?;
            for (k, &i) in at.iter().enumerate() {
                out[i as usize] = read_u32(&values[k * size(c)..], c);
            }
        }
        Ok(out)
    }

    /// The checks every accessor passes before a byte is read: its type and component type for
    /// `want`, a count of at least one and within the limits, the budget. Returns the component
    /// type and the count.
    fn check(&mut self, index: usize, want: Want) -> Result<(ComponentType, usize), Why> {
        let Some(a) = self.root.accessors.get(index) else { return Err("does not exist".into()) };
        let (Checked::Valid(t), Checked::Valid(c)) = (&a.type_, &a.component_type) else {
            return Err("has an invalid type or component type".into());
        };
        let c = c.0;
        let count = a.count.0;
        let ok = match want {
            Want::Vec3 => *t == Type::Vec3 && c == ComponentType::F32,
            Want::Index => {
                *t == Type::Scalar && matches!(c, ComponentType::U8 | ComponentType::U16 | ComponentType::U32)
            }
        };
        if !ok {
            let need = match want {
                Want::Vec3 => "VEC3 of floats (5126)",
                Want::Index => "SCALAR of unsigned bytes, shorts or ints (5121, 5123, 5125)",
            };
            return Err(format!("is {t:?} of {c:?}, where it must be {need}"));
        }
        if count == 0 {
            return Err("has no elements".into());
        }
        let made = match want {
            Want::Vec3 => {
                limits::VERTICES.check(count)?;
                12 * count
            }
            Want::Index => {
                limits::TRIANGLES.check(count / 3)?;
                4 * count
            }
        };
        self.make(made)?;
        Ok((c, count as usize))
    }

    fn elements(&mut self, index: usize, want: Want) -> Result<Vec<f32>, Why> {
        let (c, count) = self.check(index, want)?;
        let a = &self.root.accessors[index];
        let elem = 3 * size(c);
        // No view: zeros, replaced where the sparse storage says (§3.6.2.3).
        let mut out = vec![0f32; 3 * count];
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        if let Some(v) = a.buffer_view {
            let (bytes, stride) = self.view_bytes(v.value(), a.byte_offset.map_or(0, |o| o.0), count, elem)?;
            for (k, o) in out.chunks_exact_mut(3).enumerate() {
                let e = &bytes[k * stride..];
                *o.first_chunk_mut::<3>().expect("three") = [f(e), f(&e[4..]), f(&e[8..])];
            }
        }
        if let Some(s) = &a.sparse {
            let (at, values) = self.sparse(s, count, elem)?;
            for (k, &i) in at.iter().enumerate() {
                let e = &values[k * elem..];
                out[3 * i as usize..3 * i as usize + 3].copy_from_slice(&[f(e), f(&e[4..]), f(&e[8..])]);
            }
        }
        Ok(out)
    }

    /// The bytes `count` elements of `elem` bytes take in view `view` from `offset`, and the
    /// stride between them: the view within its buffer, the stride no smaller than an element,
    /// the last element within the view.
    fn view_bytes(&self, view: usize, offset: u64, count: usize, elem: usize) -> Result<(&[u8], usize), Why> {
        let Some(v) = self.root.buffer_views.get(view) else {
            return Err(format!("names buffer view {view}, which does not exist"));
        };
        let buffer = self.buffers.get(v.buffer.value()).map_or(&[][..], Vec::as_slice);
        let (start, len) = (v.byte_offset.map_or(0, |o| o.0), v.byte_length.0);
        let within = start.checked_add(len).filter(|&end| end <= buffer.len() as u64);
        let Some(end) = within else {
            return Err(format!(
                "reads buffer view {view} (bytes {start} to {start}+{len}), which runs past buffer {} ({} bytes)",
                v.buffer.value(),
                buffer.len()
            ));
        };
        let stride = v.byte_stride.map_or(0, |s| s.0);
        if stride != 0 && stride < elem {
            return Err(format!(
                "reads buffer view {view} with a byteStride of {stride}, smaller than its {elem}-byte element"
            ));
        }
        let stride = if stride == 0 { elem } else { stride };
        let need = (count as u64 - 1).checked_mul(stride as u64).and_then(|n| n.checked_add(elem as u64 + offset));
        match need {
            Some(need) if need <= len => {
                let bytes = &buffer[(start + offset) as usize..end as usize];
                Ok((bytes, stride))
            }
            _ => Err(format!(
                "needs {} bytes of buffer view {view} from its offset {offset}, which holds {len}",
                need.map_or_else(|| "more".to_string(), |n| (n - offset).to_string())
            )),
        }
    }

    /// A sparse accessor's indices (checked: fewer than `count`, increasing) and the bytes of its
    /// values (`elem` bytes each).
    fn sparse(
        &self,
        s: &gltf::json::accessor::sparse::Sparse,
        count: usize,
        elem: usize,
    ) -> Result<(Vec<u32>, &[u8]), Why> {
        let n = s.count.0;
        if n == 0 || n > count as u64 {
            return Err(format!("has a sparse count of {n}; it must be from 1 to the accessor's {count}"));
        }
        let Checked::Valid(ic) = &s.indices.component_type else {
            return Err("has sparse indices of an invalid component type".into());
        };
        let ic = ic.0;
        if !matches!(ic, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) {
            return Err(format!("has sparse indices of {ic:?}, not unsigned integers"));
        }
        let n = n as usize;
        let (ib, _) = self.view_bytes(s.indices.buffer_view.value(), s.indices.byte_offset.0, n, size(ic))?;
        let mut at = Vec::with_capacity(n);
        for k in 0..n {
            let i = read_u32(&ib[k * size(ic)..], ic);
            if i as usize >= count {
                return Err(format!("has sparse index {i} (entry {k}), past the accessor's {count} elements"));
            }
            if at.last().is_some_and(|&last| i <= last) {
                return Err(format!("has sparse indices that do not increase (entry {k}: {i})"));
            }
            at.push(i);
        }
        let (values, _) = self.view_bytes(s.values.buffer_view.value(), s.values.byte_offset.0, n, elem)?;
        Ok((at, values))
    }
}
