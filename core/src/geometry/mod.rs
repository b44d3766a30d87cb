//! Rays, axis-aligned boxes and the three ray–triangle tests.

mod aabb;
#[cfg(target_arch = "x86_64")]
pub mod avx512;
#[cfg(all(test, target_arch = "x86_64"))]
mod group_tests;
#[cfg(test)]
mod leaf_cases;
#[cfg(target_arch = "x86_64")]
pub(crate) mod packet8;
mod ray;
mod shear;
pub mod slab;
pub mod slab8;
pub mod slab_packet;
pub(crate) mod stored_triangle;
pub(crate) mod triangle;
mod triangle4;
#[cfg(target_arch = "x86_64")]
pub(crate) mod triangle8;
mod triangle_test;

pub(crate) use triangle4::leaf_triangle;

pub use aabb::Aabb;
pub use ray::Ray;
pub use stored_triangle::{intersect_stored, stored_form, MollerTrumboreStored};
pub use triangle::{double_area as triangle_double_area, MollerTrumbore, TriangleHit, TriangleIntersector, Watertight};
pub use triangle_test::{intersect_triangle, TriangleTest};
