//! Splits tracks and measurements into independent association groups: two tracks share a group
//! when some measurement passes both their gates. Groups are solved separately (and in
//! parallel), which is exact for the LMB marginals and turns one large assignment into many
//! small ones. Not for: gating itself.

/// One independent group: indices of tracks and of the measurements gated with them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Group {
    /// Track indices, increasing.
    pub tracks: Vec<usize>,
    /// Measurement indices, increasing.
    pub measurements: Vec<usize>,
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Groups from the gating table: `gated[i]` lists the measurements that pass track `i`'s gate.
/// Every track is in exactly one group; measurements gated with no track are in none. Groups
/// come ordered by their smallest track index.
pub fn partition(gated: &[Vec<usize>], n_meas: usize) -> Vec<Group> {
    let n = gated.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut owner: Vec<Option<usize>> = vec![None; n_meas];
    for (i, ms) in gated.iter().enumerate() {
        for &j in ms {
            match owner[j] {
                None => owner[j] = Some(i),
                Some(k) => {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, k));
                    if a != b {
                        parent[a.max(b)] = a.min(b);
                    }
                }
            }
        }
    }
    let mut slot: Vec<Option<usize>> = vec![None; n];
    let mut groups: Vec<Group> = Vec::new();
    for i in 0..n {
        let root = find(&mut parent, i);
        let g = *slot[root].get_or_insert_with(|| {
            groups.push(Group {
                tracks: Vec::new(),
                measurements: Vec::new(),
            });
            groups.len() - 1
        });
        groups[g].tracks.push(i);
    }
    for (j, o) in owner.iter().enumerate() {
        if let Some(i) = o {
            let root = find(&mut parent, *i);
            let g = slot[root].expect("every track has a group");
            groups[g].measurements.push(j);
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_merge_and_isolated_tracks_stand_alone() {
        // track 0 ~ z0, z1; track 1 ~ z1, z2; track 2 ~ nothing; track 3 ~ z3
        let gated = vec![vec![0, 1], vec![1, 2], vec![], vec![3]];
        let g = partition(&gated, 5);
        assert_eq!(
            g,
            vec![
                Group {
                    tracks: vec![0, 1],
                    measurements: vec![0, 1, 2]
                },
                Group {
                    tracks: vec![2],
                    measurements: vec![]
                },
                Group {
                    tracks: vec![3],
                    measurements: vec![3]
                },
            ]
        );
    }

    #[test]
    fn transitive_links() {
        let gated = vec![vec![0], vec![1], vec![0, 1]];
        let g = partition(&gated, 2);
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].tracks, vec![0, 1, 2]);
    }
}
