//! Reverse Cuthill-McKee node renumbering, for locality of the edge loops (DESIGN §5).

use std::collections::VecDeque;

/// Returns `new_of_old`: the reverse Cuthill-McKee order of a graph given as a CSR adjacency
/// (`offsets`, `neighbours`). Each connected component starts from a node of minimum degree.
pub fn reverse_cuthill_mckee(offsets: &[usize], neighbours: &[u32]) -> Vec<u32> {
    let n = offsets.len() - 1;
    let degree = |i: usize| offsets[i + 1] - offsets[i];
    let mut visited = vec![false; n];
    let mut order: Vec<u32> = Vec::with_capacity(n);
    let mut by_degree: Vec<u32> = (0..n as u32).collect();
    by_degree.sort_by_key(|&i| (degree(i as usize), i));
    let mut queue = VecDeque::new();
    let mut scratch: Vec<u32> = Vec::new();
    for &start in &by_degree {
        if visited[start as usize] {
            continue;
        }
        visited[start as usize] = true;
        queue.push_back(start);
        while let Some(i) = queue.pop_front() {
            order.push(i);
            scratch.clear();
            for &j in &neighbours[offsets[i as usize]..offsets[i as usize + 1]] {
                if !visited[j as usize] {
                    visited[j as usize] = true;
                    scratch.push(j);
                }
            }
            scratch.sort_by_key(|&j| (degree(j as usize), j));
            queue.extend(scratch.iter().copied());
        }
    }
    order.reverse();
    let mut new_of_old = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        new_of_old[old as usize] = new as u32;
    }
    new_of_old
}

/// Bandwidth of a graph under a numbering: max |new(i) - new(j)| over its edges.
pub fn bandwidth(offsets: &[usize], neighbours: &[u32], new_of_old: &[u32]) -> u32 {
    let mut bw = 0;
    for i in 0..offsets.len() - 1 {
        for &j in &neighbours[offsets[i]..offsets[i + 1]] {
            bw = bw.max(new_of_old[i].abs_diff(new_of_old[j as usize]));
        }
    }
    bw
}
