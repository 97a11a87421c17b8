//! Assur groups, read off the block-triangular form of the position Jacobian.
//!
//! The input pairs are locked: a link driven from the ground joins the fixed links, the two
//! links of a relative input become one rigid link. The rows of J are taken in the order
//! coordinate rows, input pairs' rows, then the other pairs' rows, each kept when it raises
//! the structural rank (an augmenting path of the row-column matching exists), so redundant
//! rows are the last ones of the pairs that repeat a constraint. The columns no matching can
//! reach (Dulmage-Mendelsohn's under-determined part) are links left free to move; the rest
//! is square, and its block-triangular form ([`BlockLu::blocks`], the blocks the position
//! solves use) has the input links and the Assur groups as its blocks once the blocks of one
//! link are joined. A group's class is the number of links of its largest closed contour of
//! inner pairs, or (without a contour) the largest number of inner pairs on one of its links,
//! 2 for a dyad; its order is its number of outer pairs (Artobolevsky).

use crate::linalg::BlockLu;
use crate::model::pairs::letter;
use crate::model::{BodyId, Link, Mechanism, PairId};
use petgraph::algo::tarjan_scc;
use petgraph::graph::{DiGraph, NodeIndex};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// One Assur group: a set of links of zero mobility with the pairs joining them to each
/// other and to the links solved before it.
#[derive(Debug, Clone, PartialEq)]
pub struct AssurGroup {
    /// Its links, each one body or the bodies a relative input locks into one rigid link.
    pub links: Vec<Vec<BodyId>>,
    /// Pairs between its links, and pairs joining it to links solved before it.
    pub inner_pairs: Vec<PairId>,
    pub outer_pairs: Vec<PairId>,
    /// Class (2 a dyad, 3 a triad, 4 a four-link contour...) and order (outer pairs).
    pub class: usize,
    pub order: usize,
    /// For a dyad its pairs' letters outer, inner, outer (R revolute, P prismatic), read so
    /// that it is one of RRR, RRP, RPR, PRP, RPP; for a larger group the count of each
    /// letter ("6R", "4R2P").
    pub kind: String,
    /// `class III triad 6R, order 3: distal1, distal2, distal3, platform`.
    pub description: String,
}

/// What the decomposition finds (the structure report shows it: `crate::Structure`).
pub(crate) struct Assur {
    pub input_links: Vec<BodyId>,
    pub relative_inputs: Vec<PairId>,
    pub groups: Vec<AssurGroup>,
    pub left_over: Vec<Vec<BodyId>>,
    pub left_over_mobility: i64,
}

struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n).collect())
    }
    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    /// Join the classes of i and j; the smaller root stays the root.
    fn union(&mut self, i: usize, j: usize) {
        let (a, b) = (self.find(i), self.find(j));
        self.0[a.max(b)] = a.min(b);
    }
}

/// Node of a link: 0 the ground, 1 + i body i.
fn node(link: Link) -> usize {
    match link {
        Link::Ground => 0,
        Link::Body(b) => b.0 + 1,
    }
}

fn body(link: Link) -> Option<BodyId> {
    match link {
        Link::Ground => None,
        Link::Body(b) => Some(b),
    }
}

/// Kuhn's augmenting path from row r over rows' columns; `col_row` the matching so far, `seen[c]
/// == search` marks the columns this search has visited (one array for all the searches, each
/// with its own mark: a fresh array per row cost O(rows x columns)).
fn augment(r: usize, rows: &[Vec<usize>], col_row: &mut [Option<usize>], seen: &mut [usize], search: usize) -> bool {
    for &c in &rows[r] {
        if seen[c] != search {
            seen[c] = search;
            if col_row[c].is_none_or(|r2| augment(r2, rows, col_row, seen, search)) {
                col_row[c] = Some(r);
                return true;
            }
        }
    }
    false
}

pub(crate) fn assur(mech: &Mechanism) -> Assur {
    let (n, nx) = (mech.n_bodies(), mech.n_x());
    let mut input = vec![false; mech.pairs.len()];
    for c in &mech.coordinates {
        input[c.pair.0] = true;
    }
    let mut units = UnionFind::new(n + 1);
    let (mut input_links, mut relative_inputs) = (Vec::new(), Vec::new());
    for (k, p) in mech.pairs.iter().enumerate().filter(|(k, _)| input[*k]) {
        match (body(p.a), body(p.b)) {
            (None, Some(b)) | (Some(b), None) if !input_links.contains(&b) => input_links.push(b),
            (Some(_), Some(_)) => relative_inputs.push(PairId(k)),
            _ => {}
        }
        units.union(node(p.a), node(p.b));
    }

    // Rows: each may use the columns of its pair's two bodies.
    let columns = |k: usize| -> Vec<usize> {
        let p = &mech.pairs[k];
        [p.a, p.b].into_iter().filter_map(body).flat_map(|b| 3 * b.0..3 * b.0 + 3).collect()
    };
    let mut rows: Vec<Vec<usize>> = mech.coordinates.iter().map(|c| columns(c.pair.0)).collect();
    for locked in [true, false] {
        for k in (0..mech.pairs.len()).filter(|&k| input[k] == locked) {
            rows.extend(mech.pair_rows(PairId(k)).map(|_| columns(k)));
        }
    }
    let (mut col_row, mut seen) = (vec![None; nx], vec![usize::MAX; nx]);
    let kept: Vec<usize> = (0..rows.len()).filter(|&r| augment(r, &rows, &mut col_row, &mut seen, r)).collect();
    let mut row_col = vec![0; rows.len()];
    for (c, r) in col_row.iter().enumerate() {
        if let Some(r) = r {
            row_col[*r] = c;
        }
    }
    // Under-determined part: columns reached from an unmatched one by alternating paths.
    let mut under_col: Vec<bool> = col_row.iter().map(Option::is_none).collect();
    let mut under_row = vec![false; rows.len()];
    let mut todo: Vec<usize> = (0..nx).filter(|&c| under_col[c]).collect();
    let mut kept_on: Vec<Vec<usize>> = vec![Vec::new(); nx];
    for &r in &kept {
        rows[r].iter().for_each(|&c| kept_on[c].push(r));
    }
    while let Some(c) = todo.pop() {
        for &r in &kept_on[c] {
            if !under_row[r] {
                under_row[r] = true;
                if !under_col[row_col[r]] {
                    under_col[row_col[r]] = true;
                    todo.push(row_col[r]);
                }
            }
        }
    }
    // The square rest in block-triangular form; the under-determined part is one more block.
    let square_cols: Vec<usize> = (0..nx).filter(|&c| !under_col[c]).collect();
    let square_rows: Vec<usize> = kept.iter().copied().filter(|&r| !under_row[r]).collect();
    let mut position = vec![usize::MAX; nx];
    for (i, &c) in square_cols.iter().enumerate() {
        position[c] = i;
    }
    let pattern: Vec<Vec<usize>> = square_rows
        .iter()
        .map(|&r| rows[r].iter().map(|&c| position[c]).filter(|&i| i != usize::MAX).collect())
        .collect();
    let blocks: Vec<(Vec<usize>, Vec<usize>)> = BlockLu::new(&pattern).blocks().collect();
    let under = blocks.len();
    let mut col_block = vec![under; nx];
    let mut row_block = vec![under; rows.len()];
    for (b, (rs, cs)) in blocks.iter().enumerate() {
        cs.iter().for_each(|&i| col_block[square_cols[i]] = b);
        rs.iter().for_each(|&i| row_block[square_rows[i]] = b);
    }

    // Sets of bodies: the blocks of one body, or of one locked unit, joined; then cycles.
    let mut sets = UnionFind::new(under + 1);
    let mut unit_first: Vec<Option<usize>> = vec![None; n + 1];
    for i in 0..n {
        sets.union(col_block[3 * i], col_block[3 * i + 1]);
        sets.union(col_block[3 * i], col_block[3 * i + 2]);
        let u = units.find(i + 1);
        match unit_first[u] {
            Some(j) => sets.union(col_block[3 * j], col_block[3 * i]),
            None => unit_first[u] = Some(i),
        }
    }
    let mut graph = DiGraph::<(), ()>::new();
    let nodes: Vec<NodeIndex> = (0..=under).map(|_| graph.add_node(())).collect();
    for &r in &kept {
        let s = sets.find(row_block[r]);
        for &c in &rows[r] {
            let t = sets.find(col_block[c]);
            if s != t {
                graph.add_edge(nodes[t], nodes[s], ());
            }
        }
    }
    for scc in tarjan_scc(&graph) {
        for v in &scc[1..] {
            sets.union(scc[0].index(), v.index());
        }
    }
    let body_set: Vec<usize> = (0..n).map(|i| sets.find(col_block[3 * i])).collect();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); under + 1];
    for (i, &s) in body_set.iter().enumerate() {
        members[s].push(i);
    }
    let ground = units.find(0);
    let grounded = |units: &mut UnionFind, i: usize| units.find(i + 1) == ground;
    // The links of a set: bodies grouped by locked unit, each unit and the list ascending.
    let links_of = |units: &mut UnionFind, bodies: &[usize]| -> Vec<Vec<BodyId>> {
        let mut out: Vec<(usize, Vec<BodyId>)> = Vec::new();
        for &i in bodies {
            let u = units.find(i + 1);
            match out.iter_mut().find(|(v, _)| *v == u) {
                Some((_, l)) => l.push(BodyId(i)),
                None => out.push((u, vec![BodyId(i)])),
            }
        }
        out.into_iter().map(|(_, l)| l).collect()
    };

    // Order: the fixed links first, then, among the sets whose predecessors are placed, the
    // one of fewest links, the lowest-numbered bodies first.
    let live: Vec<usize> = (0..=under).filter(|&s| !members[s].is_empty()).collect();
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); under + 1];
    for e in graph.raw_edges() {
        let (t, s) = (sets.find(e.source().index()), sets.find(e.target().index()));
        if s != t && !preds[s].contains(&t) {
            preds[s].push(t);
        }
    }
    let key = |units: &mut UnionFind, s: usize| {
        let base = members[s].iter().any(|&i| grounded(units, i));
        let links = links_of(units, &members[s]);
        (!base, s == under, links.len(), links.iter().map(|l| l[0].0).collect::<Vec<_>>())
    };
    // Kahn's order with the ready sets in a heap by key: each step takes the least ready set,
    // as a scan of all the sets each step would (O(sets^2) and more).
    let mut waiting: Vec<usize> = preds.iter().map(Vec::len).collect();
    let mut succs: Vec<Vec<usize>> = vec![Vec::new(); under + 1];
    for (s, ps) in preds.iter().enumerate() {
        ps.iter().for_each(|&t| succs[t].push(s));
    }
    let mut ready: BinaryHeap<Reverse<_>> =
        live.iter().filter(|&&s| waiting[s] == 0).map(|&s| Reverse((key(&mut units, s), s))).collect();
    let mut order: Vec<usize> = Vec::with_capacity(live.len());
    while let Some(Reverse((_, s))) = ready.pop() {
        order.push(s);
        for &t in &succs[s] {
            waiting[t] -= 1;
            if waiting[t] == 0 {
                ready.push(Reverse((key(&mut units, t), t)));
            }
        }
    }
    assert_eq!(order.len(), live.len(), "with their cycles merged the sets form a DAG: one is always ready");

    // Each set's own pairs (not inputs, a body in the set), ascending: a set's inner and outer
    // pairs are among them, found without a scan of all the pairs per set.
    let mut touching: Vec<Vec<usize>> = vec![Vec::new(); under + 1];
    for (k, p) in mech.pairs.iter().enumerate().filter(|(k, _)| !input[*k]) {
        let [a, b] = [p.a, p.b].map(|l| body(l).map(|b| body_set[b.0]));
        for s in [a, b.filter(|&b| Some(b) != a)].into_iter().flatten() {
            touching[s].push(k);
        }
    }
    let mut placed = vec![false; n + 1];
    placed[0] = true;
    let (mut groups, mut left_over) = (Vec::new(), Vec::new());
    for s in order {
        let bodies = &members[s];
        let in_set = |l: Link| body(l).is_some_and(|b| body_set[b.0] == s);
        if bodies.iter().any(|&i| grounded(&mut units, i)) {
            let loose: Vec<usize> = bodies.iter().copied().filter(|&i| !grounded(&mut units, i)).collect();
            left_over.extend(links_of(&mut units, &loose));
        } else {
            let links = links_of(&mut units, bodies);
            let (mut inner, mut outer) = (Vec::new(), Vec::new());
            for &k in &touching[s] {
                let p = &mech.pairs[k];
                if in_set(p.a) && in_set(p.b) && units.find(node(p.a)) != units.find(node(p.b)) {
                    inner.push(PairId(k));
                } else if (in_set(p.a) && placed[node(p.b)]) || (in_set(p.b) && placed[node(p.a)]) {
                    outer.push(PairId(k));
                }
            }
            let constraints: usize = inner.iter().chain(&outer).map(|&k| mech.pair_rows(k).len()).sum();
            if s != under && 3 * links.len() == constraints {
                groups.push(group(mech, links, inner, outer));
            } else {
                left_over.extend(links);
            }
        }
        bodies.iter().for_each(|&i| placed[i + 1] = true);
    }
    left_over.sort_by_key(|l| l[0].0);
    let mut in_rest = vec![false; n];
    left_over.iter().flatten().for_each(|b: &BodyId| in_rest[b.0] = true);
    let rest = |l: Link| body(l).is_some_and(|b| in_rest[b.0]);
    let constraints: usize = (0..mech.pairs.len())
        .filter(|&k| !input[k] && (rest(mech.pairs[k].a) || rest(mech.pairs[k].b)))
        .map(|k| mech.pair_rows(PairId(k)).len())
        .sum();
    let left_over_mobility = 3 * left_over.len() as i64 - constraints as i64;
    Assur { input_links, relative_inputs, groups, left_over, left_over_mobility }
}

/// Class, type and description of a group of `links` with its inner and outer pairs.
fn group(mech: &Mechanism, links: Vec<Vec<BodyId>>, inner: Vec<PairId>, outer: Vec<PairId>) -> AssurGroup {
    let link_of = |l: Link| body(l).and_then(|b| links.iter().position(|u| u.contains(&b)));
    let edges: Vec<(usize, usize)> =
        inner.iter().filter_map(|&k| Some((link_of(mech.pairs[k.0].a)?, link_of(mech.pairs[k.0].b)?))).collect();
    let class = match links.len() {
        k @ (1 | 2) => k,
        k => {
            let degree = (0..k).map(|u| edges.iter().filter(|e| e.0 == u || e.1 == u).count()).max().unwrap_or(0);
            degree.max(longest_cycle(k, &edges))
        }
    };
    let l = |k: PairId| letter(&mech.pairs[k.0].kind);
    let touching = |u: usize| {
        outer.iter().copied().find(|&k| link_of(mech.pairs[k.0].a) == Some(u) || link_of(mech.pairs[k.0].b) == Some(u))
    };
    let kind = match (links.len(), inner.as_slice(), touching(0), touching(1)) {
        (2, [i], Some(o1), Some(o2)) if outer.len() == 2 => {
            let read: String = [l(o1), l(*i), l(o2)].into_iter().collect();
            let back: String = read.chars().rev().collect();
            // R before P, the way the five classical dyads are named.
            read.max(back)
        }
        _ => {
            let all: Vec<char> = inner.iter().chain(&outer).map(|&k| l(k)).collect();
            let mut letters: Vec<char> = all.clone();
            letters.sort_by_key(|c| (*c != 'R', *c != 'P', *c));
            letters.dedup();
            letters.iter().map(|c| format!("{}{c}", all.iter().filter(|a| *a == c).count())).collect()
        }
    };
    let roman = ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"].get(class.wrapping_sub(1));
    let what = match class {
        2 => "dyad",
        3 => "triad",
        _ => "group",
    };
    let names: Vec<String> =
        links.iter().map(|u| u.iter().map(|b| mech.bodies[b.0].name.as_str()).collect::<Vec<_>>().join("+")).collect();
    let description = format!(
        "class {} {what} {kind}, order {}: {}",
        roman.map_or_else(|| class.to_string(), |r| r.to_string()),
        outer.len(),
        names.join(", ")
    );
    AssurGroup { order: outer.len(), links, inner_pairs: inner, outer_pairs: outer, class, kind, description }
}

/// Links in the longest simple cycle of a small multigraph (0 for a forest; two links
/// joined twice are no contour).
fn longest_cycle(k: usize, edges: &[(usize, usize)]) -> usize {
    fn walk(start: usize, u: usize, seen: &mut Vec<usize>, adj: &[Vec<usize>], best: &mut usize) {
        for &v in &adj[u] {
            if v == start && seen.len() >= 3 {
                *best = (*best).max(seen.len());
            } else if !seen.contains(&v) {
                seen.push(v);
                walk(start, v, seen, adj, best);
                seen.pop();
            }
        }
    }
    let mut adj = vec![Vec::new(); k];
    for &(a, b) in edges {
        adj[a].push(b);
        adj[b].push(a);
    }
    let mut best = 0;
    for u in 0..k {
        walk(u, u, &mut vec![u], &adj, &mut best);
    }
    best
}
