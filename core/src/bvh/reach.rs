//! The walk from the root of a tree that has not been checked yet (a dump read from a file, a
//! tree about to be uploaded to the GPU): depth first, without recursion and in time linear in
//! the nodes and their children however deep or tangled, each node entered once, and what a
//! tree must not have named as it is met: a child past the last node, a node reached again (on
//! the path from the root: a cycle; elsewhere: a second parent). The checker lists every such
//! fault of a dump; the GPU refuses a tree at the first.
//!
//! (`Hierarchy::of` reads the trees this crate builds, whose every child comes after its parent,
//! and checks that stronger order in parallel before it reads a big tree side by side.)

use std::ops::ControlFlow;

/// What the walk meets that a tree must not have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// Node `from` names `child`, past the last node (not followed).
    PastEnd { from: usize, child: u32 },
    /// `node` is reached again from `from` (not followed again): a cycle when it is on the path
    /// from the root to `from`, else a second parent.
    Again { from: usize, node: usize, cycle: bool },
}

/// The nodes the walk reached, the parent each was first reached from (`u32::MAX` for the root
/// and the nodes never reached), and the deepest depth it went (edges from the root).
pub struct Reach {
    pub reached: Vec<bool>,
    pub parent: Vec<u32>,
    pub depth: u32,
}

/// Walk the `n` nodes from node 0: `child(i, k)` is node `i`'s `k`-th child, `None` past its
/// last. Every fault goes to `fault`, which stops the walk by returning `Break`.
pub fn reach(
    n: usize,
    child: impl Fn(usize, usize) -> Option<u32>,
    mut fault: impl FnMut(Fault) -> ControlFlow<()>,
) -> Reach {
    let mut r = Reach { reached: vec![false; n], parent: vec![u32::MAX; n], depth: 0 };
    if n == 0 {
        return r;
    }
    let mut on_path = vec![false; n];
    // (node, its next child to follow)
    let mut stack = vec![(0usize, 0usize)];
    (r.reached[0], on_path[0]) = (true, true);
    while let Some(top) = stack.last_mut() {
        let (i, next) = *top;
        let Some(k) = child(i, next) else {
            on_path[i] = false;
            stack.pop();
            continue;
        };
        top.1 += 1;
        let met = if k as usize >= n {
            Some(Fault::PastEnd { from: i, child: k })
        } else if r.reached[k as usize] {
            Some(Fault::Again { from: i, node: k as usize, cycle: on_path[k as usize] })
        } else {
            None
        };
        if let Some(f) = met {
            if fault(f).is_break() {
                break;
            }
            continue;
        }
        let k = k as usize;
        (r.reached[k], on_path[k]) = (true, true);
        r.parent[k] = i as u32;
        stack.push((k, 0));
        r.depth = r.depth.max(stack.len() as u32 - 1);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk(children: &[&[u32]]) -> (Reach, Vec<Fault>) {
        let mut faults = Vec::new();
        let r = reach(
            children.len(),
            |i, k| children[i].get(k).copied(),
            |f| {
                faults.push(f);
                ControlFlow::Continue(())
            },
        );
        (r, faults)
    }

    #[test]
    fn a_tree_is_reached_once_with_its_parents_and_depth() {
        let (r, faults) = walk(&[&[1, 2], &[], &[3, 4], &[], &[]]);
        assert!(faults.is_empty());
        assert!(r.reached.iter().all(|&b| b));
        assert_eq!(r.parent, vec![u32::MAX, 0, 0, 2, 2]);
        assert_eq!(r.depth, 2);
    }

    #[test]
    fn cycles_second_parents_and_children_past_the_end_are_named_and_not_followed() {
        let (r, faults) = walk(&[&[1, 2], &[0, 2], &[9], &[]]);
        assert_eq!(
            faults,
            vec![
                Fault::Again { from: 1, node: 0, cycle: true },
                Fault::PastEnd { from: 2, child: 9 },
                Fault::Again { from: 0, node: 2, cycle: false },
            ]
        );
        assert_eq!(r.reached, vec![true, true, true, false]);
        let mut first = None;
        reach(
            2,
            |i, k| (i == 0 && k < 2).then_some(1),
            |f| {
                first.get_or_insert(f);
                ControlFlow::Break(())
            },
        );
        assert_eq!(first, Some(Fault::Again { from: 0, node: 1, cycle: false }));
    }
}
