//! Best-first search (algorithm A, Mařík 1993, as the paper's seven steps), generic over the
//! problem: it knows states, keys, successors and values, nothing of legs.
//!
//! 1. OPEN ← {s0}, CLOSED ← ∅.
//! 2. If OPEN is empty, there is no solution: stop.
//! 3. Take the state i with least f(i) from OPEN (f on a 1e-7 grid, [`VALUE_QUANTUM`]); among ties prefer a goal state, then the one
//!    generated first (FIFO), or last (LIFO) when [`Problem::newest_first`] says so: the paper
//!    states no tie rule.
//! 4. Move i from OPEN to CLOSED.
//! 5. If i is a goal, the solution is found: stop.
//! 6. Expand i: for each successor j compute f(j). If j is in neither list, put it on OPEN. If it
//!    is on OPEN or CLOSED with a larger f, set its f and parent and put it (back) on OPEN.
//! 7. Go to 2.
//!
//! OPEN is a binary heap with lazy deletion: a state's entry is stale once the state is closed
//! or re-entered under a newer generation number. Both lists are one node store, indexed by a
//! hash table of node numbers: a key is not stored but made again from the node's state when a
//! lookup meets it, so the index costs 8 bytes a state, not the key's size
//! ([`bytes_per_state`]).
//!
//! **Paths are exact**: each state of a returned path is its step applied to the state before
//! it, as [`Problem::successors`] made it, not merely a state under the same key. Two states
//! under one key may differ (by up to the key's quantum), so:
//! - whether a duplicate's new path is better (step 6) is judged on the state stored under the
//!   key, so a state whose f does not depend on its path, as under (1), is never re-parented
//!   for the difference between two copies; only a cheaper path re-parents;
//! - re-parenting stores the successor just made (and its f) in place of the old state and
//!   re-opens it, so the link to the new parent is exact;
//! - the node's children made from its old state keep their parent, so each link records the
//!   parent's state version it was made from. When the path is taken (at a goal, or the best
//!   partial path), a link from an older version is made again: the parent's state is expanded
//!   and the successor under the same key taken. In practice the node is re-expanded before,
//!   and its children re-parented with the better f, so this is rare (the paper's six rows
//!   never need it). A goal whose path cannot be made again (no successor falls under its key
//!   any more) is no solution and the search goes on; a partial path ends at its exact prefix.
//!
//! Replaying every rule from the start when the path is taken would be the other way; it can
//! fail on any link (a translation of exactly ΔY, a leg lifted on a margin's edge) and would
//! leave the states the search stored and ranked different from those returned.
//!
//! ```
//! use mobil_gait::search::{search, Problem, SearchEnd};
//!
//! /// Walk on the integers from 0 to 5 by +1 or +2, each move costing 1: f = moves + 0.
//! struct Line;
//! impl Problem for Line {
//!     type State = i32;
//!     type Key = i32;
//!     type Step = i32;
//!     fn key(&self, s: &i32) -> i32 { *s }
//!     fn is_goal(&self, s: &i32) -> bool { *s == 5 }
//!     fn start_value(&self, _: &i32) -> f64 { 0.0 }
//!     fn successors(&self, s: &i32, out: &mut Vec<(i32, i32)>) {
//!         if *s < 5 { out.push((1, s + 1)); out.push((2, s + 2)); }
//!     }
//!     fn value(&self, _: &i32, parent_f: f64, _: i32, _: &i32) -> f64 { parent_f + 1.0 }
//!     fn remaining(&self, s: &i32) -> f64 { f64::from(5 - s) }
//! }
//! let r = search(&Line, 0, 1000, &mut || false);
//! assert_eq!(r.end, SearchEnd::Goal);
//! // Three moves, the fewest. 0 → 2 → 4 → 5 costs as much; ties go to the state generated
//! // first (1 before 2, then 3 before 4), so the search returns 0 → 1 → 3 → 5.
//! assert_eq!(r.path.iter().map(|n| n.state).collect::<Vec<_>>(), vec![0, 1, 3, 5]);
//! assert_eq!(r.path[3].value, 3.0);
//! ```

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::hash::{Hash, Hasher};

use hashbrown::HashTable;

/// How often (in expansions) the stop callback is asked.
pub const STOP_CHECK_EVERY: u32 = 256;

/// A search problem: states, their keys, successors in order, the goal test and f.
pub trait Problem {
    /// A state (compared to tell whether re-parenting changed it).
    type State: Clone + PartialEq;
    /// The key duplicates are found by (e.g. a quantised state).
    type Key: Hash + Eq;
    /// The operator that made a successor (e.g. a rule).
    type Step: Copy;
    /// The key of a state.
    fn key(&self, s: &Self::State) -> Self::Key;
    /// Whether the state is a goal.
    fn is_goal(&self, s: &Self::State) -> bool;
    /// f of the start state.
    fn start_value(&self, s: &Self::State) -> f64;
    /// Appends the successors of `s` to `out`, in the order they are generated.
    fn successors(&self, s: &Self::State, out: &mut Vec<(Self::Step, Self::State)>);
    /// f of successor `child` made by `step` from `parent`, whose f is `parent_f`.
    fn value(&self, parent: &Self::State, parent_f: f64, step: Self::Step, child: &Self::State) -> f64;
    /// How far the state is from a goal, used only to choose the best partial path when the
    /// search ends without a goal (lower is better).
    fn remaining(&self, s: &Self::State) -> f64;
    /// Among states tied on f and on being a goal, take the one generated last (LIFO) rather
    /// than first (FIFO, the default).
    fn newest_first(&self) -> bool {
        false
    }
}

/// Why the search ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchEnd {
    /// A goal state was taken from OPEN (step 5).
    Goal,
    /// OPEN became empty (step 2): no solution.
    OpenEmpty,
    /// The expansion limit was reached.
    ExpansionLimit,
    /// The stop callback asked to stop.
    Stopped,
}

/// One state of a returned path.
#[derive(Debug, Clone)]
pub struct PathNode<S, St> {
    /// The state.
    pub state: S,
    /// The step that made it from the previous one; `None` for the start.
    pub step: Option<St>,
    /// Its f.
    pub value: f64,
}

/// The result of a search.
#[derive(Debug, Clone)]
pub struct SearchResult<S, St> {
    /// Start to goal, or, when no goal was found, start to the state with least
    /// [`Problem::remaining`] among those generated (ties: the first generated), cut after its
    /// last exact link if a later one cannot be made again. Each state is exactly its step
    /// applied to the one before.
    pub path: Vec<PathNode<S, St>>,
    /// Why it ended.
    pub end: SearchEnd,
    /// States expanded: moved to CLOSED and their successors generated (re-expansions of
    /// reopened states included; the goal, closed at step 4 and never expanded, is not).
    pub expanded: u32,
    /// Successors produced by the problem (duplicates of known states included).
    pub generated: u32,
    /// Distinct states seen (by key).
    pub distinct: u32,
}

struct Node<S, St> {
    state: S,
    parent: u32,
    step: Option<St>,
    value: f64,
    generation: u32,
    goal: bool,
    closed: bool,
    /// Bumped each time re-parenting replaces the state.
    version: u32,
    /// The parent's `version` when `state` was made from it: the link is exact while they agree.
    parent_version: u32,
}

/// An OPEN entry: least f (on the [`VALUE_QUANTUM`] grid) first, then a goal, then the least
/// `order`: the generation (oldest first) or its complement (newest first), from which the
/// generation is also recovered ([`Order`]). 24 bytes.
struct Entry {
    value: i64,
    order: u32,
    node: u32,
    goal: bool,
}

/// Generation numbers and the heap's order: equal (oldest first) or complements (newest first).
#[derive(Clone, Copy)]
struct Order {
    newest: bool,
}

impl Order {
    fn of(self, generation: u32) -> u32 {
        if self.newest {
            u32::MAX - generation
        } else {
            generation
        }
    }

    /// The generation an entry was made under (the map is its own inverse).
    fn generation(self, entry: &Entry) -> u32 {
        self.of(entry.order)
    }
}

/// An index slot: a node number and 32 bits of its key's hash, compared before the key is made
/// again from the node's state.
#[derive(Clone, Copy)]
struct Slot {
    node: u32,
    hash: u32,
}

/// A key's hash: FxHash folded to 32 bits (kept in the slot), spread again for the table.
fn key_hash<K: Hash>(key: &K) -> u32 {
    let mut h = FxHasher::default();
    key.hash(&mut h);
    let full = h.finish();
    (full >> 32) as u32 ^ full as u32
}

fn table_hash(hash: u32) -> u64 {
    u64::from(hash).wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    /// Reversed, for the max-heap: the entry to take first is the greatest.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .value
            .cmp(&self.value)
            .then(self.goal.cmp(&other.goal))
            .then(other.order.cmp(&self.order))
    }
}

/// Bytes a search stores per distinct state of problem `P`: its node, its index slot (with the
/// table's control byte, at its load factor of 7/8) and one OPEN entry — the estimate the
/// long-search bench prints; re-opened states add an OPEN entry each.
pub fn bytes_per_state<P: Problem>() -> usize {
    use std::mem::size_of;
    size_of::<Node<P::State, P::Step>>() + (size_of::<Slot>() + 1) * 8 / 7 + size_of::<Entry>()
}

/// FxHash (rustc's): one multiply per word, ample for quantised integer keys.
#[derive(Default, Clone, Copy)]
pub struct FxHasher(u64);

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

/// f is compared on a grid of this size: (2) and (3) accumulate f along the path, so two
/// states whose f is equal in exact arithmetic (the same body pose reached by different
/// paths, which (1) ranks as an exact tie) differ by rounding noise of 1e-15..1e-12. On the
/// grid they tie, and the tie rule (goal first, then FIFO or LIFO) decides, as it does under (1); a
/// state is re-parented only when its f improves by a grid step. No rule changes f by less
/// than the key quantum's effect (≥ 1e-4 at the default 1e-3), far above the grid.
pub const VALUE_QUANTUM: f64 = 1e-7;

/// f on the [`VALUE_QUANTUM`] grid (a NaN ranks last).
pub fn rank(f: f64) -> i64 {
    if f.is_nan() {
        i64::MAX
    } else {
        (f / VALUE_QUANTUM).round() as i64
    }
}

/// Best-first search from `start` until a goal is taken from OPEN, OPEN is empty,
/// `max_expansions` states have been expanded, or `stop()` returns true (asked every
/// [`STOP_CHECK_EVERY`] expansions).
///
/// Counts and node numbers are `u32`: a search must stay below 2^32 generated states (the
/// node bounds it by `max_generated_states`; beyond, the tie order of older states would wrap).
///
/// The returned path is exact: each state is its step applied to the state before it, as
/// [`Problem::successors`] made it (see the module's documentation for how re-parenting keeps
/// this, and [`SearchResult::path`] for the rare goal whose path cannot be rebuilt).
pub fn search<P: Problem>(
    problem: &P,
    start: P::State,
    max_expansions: u32,
    stop: &mut dyn FnMut() -> bool,
) -> SearchResult<P::State, P::Step> {
    let mut nodes: Vec<Node<P::State, P::Step>> = Vec::new();
    let mut index: HashTable<Slot> = HashTable::new();
    let mut open = BinaryHeap::new();
    let mut generation: u32 = 0;
    let (mut expanded, mut generated) = (0u32, 0u32);
    let mut succ: Vec<(P::Step, P::State)> = Vec::new();

    let f0 = problem.start_value(&start);
    let goal0 = problem.is_goal(&start);
    let mut best = (problem.remaining(&start), 0u32);
    let start_hash = key_hash(&problem.key(&start));
    index.insert_unique(
        table_hash(start_hash),
        Slot {
            node: 0,
            hash: start_hash,
        },
        |s| table_hash(s.hash),
    );
    nodes.push(Node {
        state: start,
        parent: u32::MAX,
        step: None,
        value: f0,
        generation,
        goal: goal0,
        closed: false,
        version: 0,
        parent_version: 0,
    });
    let order = Order {
        newest: problem.newest_first(),
    };
    open.push(Entry {
        value: rank(f0),
        goal: goal0,
        order: order.of(generation),
        node: 0,
    });

    let mut goal_path = None;
    let end = loop {
        // Step 2.
        let Some(e) = open.pop() else {
            break SearchEnd::OpenEmpty;
        };
        let i = e.node as usize;
        if nodes[i].closed || nodes[i].generation != order.generation(&e) {
            continue; // stale entry: lazy deletion
        }
        // Steps 3–5.
        nodes[i].closed = true;
        if nodes[i].goal {
            match exact_path(problem, &nodes, e.node, &mut succ) {
                Ok(path) if path.last().is_some_and(|n| problem.is_goal(&n.state)) => {
                    goal_path = Some(path);
                    break SearchEnd::Goal;
                }
                // The goal's path cannot be rebuilt exactly: it is no solution; go on.
                _ => continue,
            }
        }
        if expanded >= max_expansions {
            nodes[i].closed = false;
            break SearchEnd::ExpansionLimit;
        }
        if expanded % STOP_CHECK_EVERY == 0 && expanded > 0 && stop() {
            nodes[i].closed = false;
            break SearchEnd::Stopped;
        }
        expanded += 1;
        // Step 6.
        succ.clear();
        problem.successors(&nodes[i].state, &mut succ);
        let (parent_f, parent_version) = (nodes[i].value, nodes[i].version);
        for (step, child) in succ.drain(..) {
            generated += 1;
            let key = problem.key(&child);
            let hash = key_hash(&key);
            let found = index
                .find(table_hash(hash), |s| {
                    s.hash == hash && nodes.get(s.node as usize).is_some_and(|n| problem.key(&n.state) == key)
                })
                .map(|s| s.node);
            match found {
                None => {
                    let f = problem.value(&nodes[i].state, parent_f, step, &child);
                    generation = generation.wrapping_add(1);
                    let id = nodes.len() as u32;
                    let goal = problem.is_goal(&child);
                    let rem = problem.remaining(&child);
                    if rem < best.0 {
                        best = (rem, id);
                    }
                    index.insert_unique(table_hash(hash), Slot { node: id, hash }, |s| table_hash(s.hash));
                    nodes.push(Node {
                        state: child,
                        parent: i as u32,
                        step: Some(step),
                        value: f,
                        generation,
                        goal,
                        closed: false,
                        version: 0,
                        parent_version,
                    });
                    open.push(Entry {
                        value: rank(f),
                        goal,
                        order: order.of(generation),
                        node: id,
                    });
                }
                Some(id) if id as usize != i => {
                    // Whether the new path is better is judged on the state already stored
                    // under the key, so a state whose f does not depend on its path, as under
                    // (1), is never re-parented for the quantum's difference between two of its
                    // copies; only a cheaper path re-parents.
                    let stored = &nodes[id as usize].state;
                    let f_path = problem.value(&nodes[i].state, parent_f, step, stored);
                    if rank(f_path) < rank(nodes[id as usize].value) {
                        // Re-parented, the node takes the state this step makes from its new
                        // parent, so the link is exact; its f is that state's.
                        let f = problem.value(&nodes[i].state, parent_f, step, &child);
                        generation = generation.wrapping_add(1);
                        let n = &mut nodes[id as usize];
                        if n.state != child {
                            // The copy may lie on the other side of the goal's boundary.
                            n.goal = problem.is_goal(&child);
                            n.state = child;
                            n.version = n.version.wrapping_add(1);
                        }
                        n.value = f;
                        n.parent = i as u32;
                        n.parent_version = parent_version;
                        n.step = Some(step);
                        n.generation = generation;
                        n.closed = false;
                        open.push(Entry {
                            value: rank(f),
                            goal: n.goal,
                            order: order.of(generation),
                            node: id,
                        });
                    }
                }
                Some(_) => {} // a state is never its own better parent
            }
        }
    };

    let path = match goal_path {
        Some(path) => path,
        None => {
            // The best partial path: exact up to the first link that cannot be rebuilt.
            match exact_path(problem, &nodes, best.1, &mut succ) {
                Ok(path) | Err(path) => path,
            }
        }
    };
    SearchResult {
        path,
        end,
        expanded,
        generated,
        distinct: nodes.len() as u32,
    }
}

/// The path from the start to node `at`, every state exactly its step applied to the state
/// before it. A link made from a state its parent no longer holds (the parent was re-parented
/// to a copy within the key afterwards) is made again: the parent's current state is expanded
/// and its successor under the same key taken (the first generated). `Err` holds the exact
/// prefix when some successor under the key is no longer generated.
#[allow(clippy::type_complexity)]
fn exact_path<P: Problem>(
    problem: &P,
    nodes: &[Node<P::State, P::Step>],
    at: u32,
    succ: &mut Vec<(P::Step, P::State)>,
) -> Result<Vec<PathNode<P::State, P::Step>>, Vec<PathNode<P::State, P::Step>>> {
    let mut chain = Vec::new();
    let mut n = at;
    // A parent chain is at most as long as the node list (a guard against a value function
    // under which re-parenting could close a cycle).
    while n != u32::MAX && chain.len() <= nodes.len() {
        chain.push(n);
        n = nodes[n as usize].parent;
    }
    chain.reverse();
    let mut path: Vec<PathNode<P::State, P::Step>> = Vec::with_capacity(chain.len());
    // Whether the path's last state differs from the one its node stores (it was made again).
    let mut rebuilt = false;
    for (k, &id) in chain.iter().enumerate() {
        let node = &nodes[id as usize];
        let exact = k == 0 || (!rebuilt && node.parent_version == nodes[chain[k - 1] as usize].version);
        if exact {
            path.push(PathNode {
                state: node.state.clone(),
                step: node.step,
                value: node.value,
            });
            continue;
        }
        let Some(prev) = path.last() else {
            return Err(path);
        };
        succ.clear();
        problem.successors(&prev.state, succ);
        let key = problem.key(&node.state);
        let Some(pos) = succ.iter().position(|(_, s)| problem.key(s) == key) else {
            return Err(path);
        };
        let (step, state) = succ.swap_remove(pos);
        let value = problem.value(&prev.state, prev.value, step, &state);
        rebuilt = state != node.state;
        path.push(PathNode {
            state,
            step: Some(step),
            value,
        });
    }
    Ok(path)
}
