//! Lists regrouped by mesh node for [`super::near`]: the pairs of reach boxes and item boxes
//! found by querying the hierarchy of reach boxes, counted into per-node rows
//! ([`pairs_by_node`]), and the per-node lists written by parallel runs of nodes, joined
//! ([`join_offsets`], [`concat`]).

use super::near::NodeBoxes;
use rayon::prelude::*;

/// Nodes per parallel task of the list passes (a few thousand near nodes of long lists make
/// several tasks).
const CHUNK: usize = 256;

/// `run` over `nodes` by runs of [`CHUNK`], in parallel, the results in the order of `nodes`
/// (the same for any number of threads).
pub(super) fn par_node_chunks<T: Send>(
    nodes: &[u32],
    run: impl Fn(&[u32]) -> T + Sync + Send,
) -> Vec<T> {
    nodes.par_chunks(CHUNK).map(run).collect()
}

/// The pairs of a reach box of `boxes` and one of the `n_items` item boxes (`box_of`) that
/// overlap, grouped by node: the nodes with any (ascending), and per node of the mesh the offsets
/// of its items in the second list (each node's ascending). Each item box queries the hierarchy
/// of reach boxes, by runs of items in parallel (a query costs about what it finds: the reach
/// boxes are all of a size), and the pairs are regrouped by node by counting, in item order.
pub(super) fn pairs_by_node(
    boxes: &NodeBoxes,
    n_items: usize,
    box_of: impl Fn(usize) -> ([f64; 3], [f64; 3]) + Sync,
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let n = boxes.len();
    // Per run of items: the nodes each item box meets, and how many.
    let found: Vec<(Vec<u32>, Vec<u32>)> = (0..n_items.div_ceil(ITEMS))
        .into_par_iter()
        .map(|c| {
            let (mut nodes, mut counts) = (Vec::new(), Vec::new());
            for r in c * ITEMS..((c + 1) * ITEMS).min(n_items) {
                let start = nodes.len();
                let (lo, hi) = box_of(r);
                boxes.tree.for_each_overlap(&lo, &hi, |i| nodes.push(i));
                counts.push((nodes.len() - start) as u32);
            }
            (nodes, counts)
        })
        .collect();
    let mut offsets = vec![0u32; n + 1];
    for (nodes, _) in &found {
        for &i in nodes {
            offsets[i as usize + 1] += 1;
        }
    }
    let listed: Vec<u32> = (0..n as u32).filter(|&i| offsets[i as usize + 1] > 0).collect();
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    // Items in ascending order, so each node's come out ascending.
    let mut next = offsets.clone();
    let mut kept = vec![0u32; offsets[n] as usize];
    let mut r = 0u32;
    for c in 0..found.len() {
        let (nodes, counts) = &found[c];
        let mut at = 0;
        for &count in counts {
            for &i in &nodes[at..at + count as usize] {
                kept[next[i as usize] as usize] = r;
                next[i as usize] += 1;
            }
            at += count as usize;
            r += 1;
        }
    }
    (listed, offsets, kept)
}

/// Item boxes per parallel task of [`pairs_by_node`].
const ITEMS: usize = 256;

/// The per-node offsets of lists written by runs of the ascending `candidates`
/// ([`par_node_chunks`]; run `c` listed the nodes `runs[c].0` with `runs[c].1` items each): the
/// listed nodes, ascending, and the offsets of each mesh node's items in the joined list (`n + 1`
/// of them), filled in parallel, each run the offsets of the nodes from its first candidate to
/// the next run's.
pub(super) fn join_offsets(
    n: usize,
    candidates: &[u32],
    runs: &[(&[u32], &[u32])],
) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    let mut listed = vec![0u32; runs.iter().map(|r| r.0.len()).sum()];
    let mut jobs = Vec::with_capacity(runs.len());
    let (mut rest_offsets, mut rest_listed) = (&mut offsets[1..], &mut listed[..]);
    let (mut first, mut base) = (0usize, 0u32);
    for (c, &(nodes, counts)) in runs.iter().enumerate() {
        let end = candidates.get((c + 1) * CHUNK).map_or(n, |&i| i as usize);
        let (ends, rest) = std::mem::take(&mut rest_offsets).split_at_mut(end - first);
        rest_offsets = rest;
        let (to, rest) = std::mem::take(&mut rest_listed).split_at_mut(nodes.len());
        rest_listed = rest;
        jobs.push((first, base, ends, to, nodes, counts));
        base += counts.iter().sum::<u32>();
        first = end;
    }
    jobs.into_par_iter().for_each(|(first, mut end, ends, to, nodes, counts)| {
        to.copy_from_slice(nodes);
        // The end of each listed node's items, held over the unlisted nodes up to the next.
        let mut from = 0;
        for (&i, &c) in nodes.iter().zip(counts) {
            let k = i as usize - first;
            ends[from..k].fill(end);
            end += c;
            ends[k] = end;
            from = k + 1;
        }
        ends[from..].fill(end);
    });
    (listed, offsets)
}

/// The slices of `parts` one after the other, copied in parallel.
pub(super) fn concat<T: Copy + Default + Send + Sync>(parts: &[&[T]]) -> Vec<T> {
    let mut out = vec![T::default(); parts.iter().map(|p| p.len()).sum()];
    let mut jobs = Vec::with_capacity(parts.len());
    let mut rest = &mut out[..];
    for &part in parts {
        let (to, r) = std::mem::take(&mut rest).split_at_mut(part.len());
        rest = r;
        jobs.push((to, part));
    }
    jobs.into_par_iter().for_each(|(to, part)| to.copy_from_slice(part));
    out
}
