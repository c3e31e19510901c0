//! The search tree of one BFS side: nodes in generation order with parent links, and a hash map from
//! state to node for duplicate detection.

use std::hash::Hash;

use rustc_hash::FxHashMap;

const ROOT: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct Node<S> {
    state: S,
    parent: u32,
    action: u16,
}

pub(super) struct Tree<S> {
    nodes: Vec<Node<S>>,
    index: FxHashMap<S, u32>,
    /// Nodes of the deepest completed layer are `layer_start..nodes.len()` before expansion starts.
    pub(super) layer_start: usize,
    pub(super) depth: usize,
}

impl<S: Copy + Eq + Hash> Tree<S> {
    pub(super) fn new(root: S) -> Self {
        let mut index = FxHashMap::default();
        index.insert(root, 0);
        Tree { nodes: vec![Node { state: root, parent: ROOT, action: 0 }], index, layer_start: 0, depth: 0 }
    }

    pub(super) fn len(&self) -> usize {
        self.nodes.len()
    }

    pub(super) fn state(&self, node: usize) -> S {
        self.nodes[node].state
    }

    pub(super) fn find(&self, state: &S) -> Option<usize> {
        self.index.get(state).map(|&i| i as usize)
    }

    /// Adds `state` unless already present; returns its new node index.
    pub(super) fn insert(&mut self, state: S, parent: usize, action: usize) -> Option<usize> {
        let next = self.nodes.len() as u32;
        let mut fresh = false;
        self.index.entry(state).or_insert_with(|| {
            fresh = true;
            next
        });
        if !fresh {
            return None;
        }
        self.nodes.push(Node { state, parent: parent as u32, action: action as u16 });
        Some(next as usize)
    }

    /// Actions from the root to `node`.
    pub(super) fn path_to(&self, mut node: usize) -> Vec<usize> {
        let mut actions = Vec::new();
        while self.nodes[node].parent != ROOT {
            actions.push(self.nodes[node].action as usize);
            node = self.nodes[node].parent as usize;
        }
        actions.reverse();
        actions
    }

    /// Bytes held by the node list and the hash map (capacity, not length: that is what is allocated).
    pub(super) fn memory_bytes(&self) -> usize {
        let slot = std::mem::size_of::<S>() + std::mem::size_of::<u32>() + 1;
        self.nodes.capacity() * std::mem::size_of::<Node<S>>() + self.index.capacity() * slot
    }
}
