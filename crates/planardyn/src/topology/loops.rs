//! Independent loops of the body-pair graph (links are nodes, the ground one of them; pairs
//! are edges): a breadth-first spanning forest, each pair outside it closing one loop.

use crate::model::{BodyId, Link, Mechanism, PairId};
use petgraph::graph::{NodeIndex, UnGraph};
use petgraph::visit::EdgeRef;
use std::collections::VecDeque;

/// An independent loop: `links[0]`, `pairs[0]`, `links[1]`, ..., `pairs[k - 1]`, back to
/// `links[0]`; the last pair is the one outside the spanning tree that closes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    pub closing_pair: PairId,
    pub links: Vec<Link>,
    pub pairs: Vec<PairId>,
}

fn link(node: NodeIndex) -> Link {
    match node.index() {
        0 => Link::Ground,
        i => Link::Body(BodyId(i - 1)),
    }
}

fn node(link: Link) -> NodeIndex {
    NodeIndex::new(match link {
        Link::Ground => 0,
        Link::Body(b) => b.0 + 1,
    })
}

/// A loop basis (pairs - links + components loops) and whether every link is connected to
/// the ground.
pub(crate) fn loops(mech: &Mechanism) -> (Vec<Loop>, bool) {
    let mut graph = UnGraph::<(), PairId>::with_capacity(mech.n_bodies() + 1, mech.pairs.len());
    for _ in 0..=mech.n_bodies() {
        graph.add_node(());
    }
    for (k, p) in mech.pairs.iter().enumerate() {
        graph.add_edge(node(p.a), node(p.b), PairId(k));
    }
    // Breadth-first from the ground, then from any link not reached yet.
    let mut parent: Vec<Option<Option<(NodeIndex, PairId)>>> = vec![None; graph.node_count()];
    let mut components = 0;
    for root in graph.node_indices() {
        if parent[root.index()].is_some() {
            continue;
        }
        components += 1;
        parent[root.index()] = Some(None);
        let mut todo = VecDeque::from([root]);
        while let Some(u) = todo.pop_front() {
            let mut edges: Vec<_> = graph.edges(u).map(|e| (*e.weight(), e.source(), e.target())).collect();
            edges.sort_by_key(|e| e.0 .0);
            for (pair, s, t) in edges {
                let v = if s == u { t } else { s };
                if parent[v.index()].is_none() {
                    parent[v.index()] = Some(Some((u, pair)));
                    todo.push_back(v);
                }
            }
        }
    }
    let up = |v: NodeIndex| parent[v.index()].flatten();
    let to_root = |mut v: NodeIndex| {
        let mut path = vec![v];
        while let Some((p, _)) = up(v) {
            v = p;
            path.push(v);
        }
        path
    };
    let tree = |k: PairId| parent.iter().any(|p| matches!(p, Some(Some((_, q))) if *q == k));
    let mut out = Vec::new();
    for (k, p) in mech.pairs.iter().enumerate().map(|(k, p)| (PairId(k), p)) {
        if tree(k) {
            continue;
        }
        let (pa, pb) = (to_root(node(p.a)), to_root(node(p.b)));
        let common = *pa.iter().find(|l| pb.contains(l)).expect("one component");
        let down: Vec<NodeIndex> = pb[..pb.iter().position(|&l| l == common).expect("on the path")].to_vec();
        let mut links: Vec<Link> = Vec::new();
        let mut pairs = Vec::new();
        for &l in &pa[..=pa.iter().position(|&l| l == common).expect("on the path")] {
            links.push(link(l));
            if l != common {
                pairs.push(up(l).expect("below the common link").1);
            }
        }
        for &l in down.iter().rev() {
            links.push(link(l));
            pairs.push(up(l).expect("below the common link").1);
        }
        pairs.push(k);
        out.push(Loop { closing_pair: k, links, pairs });
    }
    debug_assert_eq!(out.len() + graph.node_count(), mech.pairs.len() + components);
    (out, components == 1)
}
