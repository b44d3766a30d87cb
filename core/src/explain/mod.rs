//! What explains a BVH, above the builders, the walks and the renderer: the checker of an
//! imported tree. Nothing here traces or builds by its own means: every figure comes from the same
//! build and traversal code that renders.

pub mod check;
pub mod grade;
pub mod inspect;
pub mod ray_kinds;
pub mod replay;
pub mod replay_film;
pub mod timing;
pub mod visits;
pub mod words;
