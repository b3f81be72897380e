//! The traversal stack: the children still to visit, with their entry
//! distances, in a fixed array (nothing is allocated per ray).

use super::build::MAX_DEPTH;
use super::wide::{Link, WideNode, WIDTH};
use glam::Vec4;

/// Entries in the traversal stack. A visit pushes at most three children (the
/// fourth is visited next), and a node at depth `d` is visited with at most `3d`
/// entries on the stack; the depth of the wide tree is at most the binary tree's,
/// at most [`MAX_DEPTH`]. One more slot takes the write above the top that
/// [`TraversalStack::order`] does not keep.
const STACK_SIZE: usize = 3 * MAX_DEPTH + 1;

/// Children still to visit with their entry distances, in a fixed array.
pub(super) struct TraversalStack {
    links: [Link; STACK_SIZE],
    enter: [f32; STACK_SIZE],
    len: usize,
}

impl TraversalStack {
    pub(super) const fn new() -> Self {
        Self {
            links: [Link::UNUSED; STACK_SIZE],
            enter: [0.0; STACK_SIZE],
            len: 0,
        }
    }

    /// Empties the stack for a new ray.
    #[inline]
    pub(super) fn clear(&mut self) {
        self.len = 0;
    }

    #[inline]
    fn push(&mut self, link: Link, t_enter: f32) {
        self.links[self.len] = link;
        self.enter[self.len] = t_enter;
        self.len += 1;
    }

    /// Pops children until one the ray enters before `t_max`, skipping those a
    /// closer hit found since they were pushed has ruled out.
    #[inline]
    pub(super) fn pop_before(&mut self, t_max: f32) -> Option<Link> {
        while self.len > 0 {
            self.len -= 1;
            if self.enter[self.len] < t_max {
                return Some(self.links[self.len]);
            }
        }
        None
    }

    /// Of the children of `node` whose bits are set in `hits` (at least one),
    /// returns the one entered first and pushes the others, farthest first, so that
    /// they are popped front to back. (Which of two equally near children goes
    /// first changes no query's answer; see [`super::Bvh::closest_hit`].)
    ///
    /// One or two children (95% of the nodes an incoherent ray enters) take the
    /// same path, without a branch on which: the far child is written just above
    /// the top of the stack and kept only if it is not the near one. Measured (A/B
    /// in one process, incoherent streams, one core): 6–10% more rays per second on
    /// 10k, 1M and 4M triangles than branching on the count.
    #[inline(always)]
    pub(super) fn order(&mut self, node: &WideNode, hits: u32, enter: Vec4) -> Link {
        debug_assert!(hits != 0);
        let rest = hits & (hits - 1);
        if rest & rest.wrapping_sub(1) != 0 {
            return self.order_many(node, hits, enter);
        }
        let first = hits.trailing_zeros() as usize;
        let last = (31 - hits.leading_zeros()) as usize;
        let enter = enter.to_array();
        // On a tie the later lane goes first, as in `order_many`.
        let (near, far) = if enter[last] <= enter[first] {
            (last, first)
        } else {
            (first, last)
        };
        self.links[self.len] = node.links[far];
        self.enter[self.len] = enter[far];
        self.len += usize::from(rest != 0);
        node.links[near]
    }

    /// [`TraversalStack::order`] for three or four children: an insertion sort.
    #[inline(never)]
    fn order_many(&mut self, node: &WideNode, hits: u32, enter: Vec4) -> Link {
        let enter = enter.to_array();
        let mut lanes = [0usize; WIDTH];
        let mut n = 0;
        for lane in crate::lanes::each_set(hits) {
            // Farthest first.
            let mut j = n;
            while j > 0 && enter[lanes[j - 1]] < enter[lane] {
                lanes[j] = lanes[j - 1];
                j -= 1;
            }
            lanes[j] = lane;
            n += 1;
        }
        for &lane in &lanes[..n - 1] {
            self.push(node.links[lane], enter[lane]);
        }
        node.links[lanes[n - 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The children `order` hands back for `hits` with entry distances `enter`:
    /// the one to visit now, then the stack's, as popped (with no pruning).
    fn visit_order(hits: u32, enter: [f32; 4], stacked: &[(Link, f32)]) -> Vec<usize> {
        let mut node = WideNode::EMPTY;
        for lane in 0..WIDTH {
            node.links[lane] = Link::interior(100 + lane);
        }
        let mut stack = TraversalStack::new();
        for &(link, t) in stacked {
            stack.push(link, t);
        }
        let first = stack.order(&node, hits, Vec4::from_array(enter));
        let mut order = vec![first.node() - 100];
        while let Some(link) = stack.pop_before(f32::INFINITY) {
            if link.node() < 100 {
                break;
            }
            order.push(link.node() - 100);
        }
        order
    }

    #[test]
    fn order_visits_the_hit_children_front_to_back_whatever_their_count() {
        let enter = [3.0, 1.0, 4.0, 2.0];
        // One child: nothing pushed, although the far slot is written above the top.
        let below = [(Link::interior(7), 9.0)];
        assert_eq!(visit_order(0b0100, enter, &below), [2]);
        let mut stack = TraversalStack::new();
        stack.push(Link::interior(7), 9.0);
        let node = WideNode::EMPTY;
        stack.order(&node, 0b0100, Vec4::from_array(enter));
        assert_eq!(stack.len, 1, "a lone child leaves the stack as it was");
        // Two children, in either lane order.
        assert_eq!(visit_order(0b0011, enter, &below), [1, 0]);
        assert_eq!(visit_order(0b0101, enter, &below), [0, 2]);
        assert_eq!(visit_order(0b1100, enter, &below), [3, 2]);
        // Three and four: sorted.
        assert_eq!(visit_order(0b0111, enter, &below), [1, 0, 2]);
        assert_eq!(visit_order(0b1111, enter, &below), [1, 3, 0, 2]);
        // Ties: the later lane first, with two children as with more.
        let tied = [2.0, 2.0, 2.0, 2.0];
        assert_eq!(visit_order(0b0011, tied, &[]), [1, 0]);
        assert_eq!(visit_order(0b1010, tied, &[]), [3, 1]);
        assert_eq!(visit_order(0b1011, tied, &[]), [3, 1, 0]);
    }
}
