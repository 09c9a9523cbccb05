//! The search: optimality on small instances against an independent exhaustive search, every
//! plan statically stable and made of single rules, (2) ranking states exactly as (1), the
//! limits (expansions, stop callback, an exhausted state space) ending with a clear reason.

use mobil_gait::planner::{state_key, GaitProblem, StateKey};
use mobil_gait::search::{search, Problem, SearchEnd, STOP_CHECK_EVERY};
use mobil_gait::{
    is_stable, is_supported, plan, vzd, BodyPose, Evaluation, GaitConfig, GaitState, PlanFailure, QuadrupedModel, Rule,
    RuleSet,
};
use nalgebra::Point2;
use std::cell::RefCell;
use std::collections::{HashMap, VecDeque};
use std::f64::consts::PI;

const GOAL: Point2<f64> = Point2::new(-10.0, 10.0);

fn paper_start(model: &QuadrupedModel, set: RuleSet) -> GaitState {
    let phi = match set {
        RuleSet::A => PI / 4.0,
        RuleSet::B => 1.5 * PI,
    };
    GaitState::nominal(model, BodyPose { x: 0.0, y: 0.0, phi })
}

/// Fewest leg moves from `start` to a state within `tol` of `goal`, by 0-1 breadth-first search
/// over the rules (body moves cost 0, leg moves 1), states merged by the same key; `None` if
/// none within `cap` states.
fn fewest_leg_moves(
    m: &QuadrupedModel,
    cfg: &GaitConfig,
    set: RuleSet,
    start: GaitState,
    goal: Point2<f64>,
    cap: usize,
) -> Option<u32> {
    let mut best: HashMap<StateKey, u32> = HashMap::new();
    let mut dq = VecDeque::new();
    best.insert(state_key(&start, cfg.key_quantum), 0);
    dq.push_back((start, 0u32));
    while let Some((s, c)) = dq.pop_front() {
        if best.get(&state_key(&s, cfg.key_quantum)).is_some_and(|&b| b < c) {
            continue;
        }
        if vzd(&s, goal) <= cfg.goal_tolerance {
            return Some(c);
        }
        if best.len() > cap {
            return None;
        }
        for rule in Rule::all(set) {
            for next in rule.apply(m, cfg, &s, goal).into_iter().flatten() {
                let w = u32::from(rule.moving_leg().is_some());
                let k = state_key(&next, cfg.key_quantum);
                if best.get(&k).is_none_or(|&b| c + w < b) {
                    best.insert(k, c + w);
                    if w == 0 {
                        dq.push_front((next, c));
                    } else {
                        dq.push_back((next, c + 1));
                    }
                }
            }
        }
    }
    None
}

#[test]
fn uniform_cost_finds_the_fewest_leg_moves() {
    // Evaluation (3) with k1 = k2 = 0 and k3 = 1 is f = leg moves on the path: the search is
    // uniform-cost and must return a plan with the fewest leg moves, which an independent 0-1
    // breadth-first search over the same rules finds too.
    let m = QuadrupedModel::default();
    let cfg = GaitConfig {
        a3_k1: 0.0,
        a3_k2: 0.0,
        a3_k3: 1.0,
        b3_k1: 0.0,
        b3_k2: 0.0,
        b3_k3: 1.0,
        goal_tolerance: 0.3,
        ..GaitConfig::default()
    };
    let start = GaitState::nominal(&m, BodyPose::default());
    for (set, goal) in [
        (RuleSet::A, Point2::new(0.0, 3.0)),
        (RuleSet::A, Point2::new(0.0, 4.5)),
        (RuleSet::A, Point2::new(-1.0, 3.0)),
        (RuleSet::B, Point2::new(0.0, 3.0)),
    ] {
        let p = plan(&m, &cfg, &start, goal, set, Evaluation::Three, 500_000, &mut || false);
        assert!(p.success, "{set} to {goal:?}: {:?}", p.failure);
        let exhaustive = fewest_leg_moves(&m, &cfg, set, start, goal, 2_000_000).unwrap();
        assert_eq!(p.leg_moves() as u32, exhaustive, "{set} to {goal:?}");
        // f of the goal is the plan's leg moves (k3 = 1, no heuristic).
        let last = p.steps.last().unwrap();
        assert!((last.evaluation - exhaustive as f64).abs() < 1e-9);
    }
}

/// Whether two states agree to `eps` in every coordinate (φ modulo 2π).
fn same_state(a: &GaitState, b: &GaitState, eps: f64) -> bool {
    let dphi = (a.body.phi - b.body.phi + PI).rem_euclid(2.0 * PI) - PI;
    (a.body.x - b.body.x).abs() <= eps
        && (a.body.y - b.body.y).abs() <= eps
        && dphi.abs() <= eps
        && a.feet.iter().zip(&b.feet).all(|(p, q)| (p - q).abs().max() <= eps)
}

/// Checks a plan: starts at `start`, each state valid and exactly its rule applied to the
/// previous state (to 1e-12 in every coordinate: an executed plan moves no planted foot), a leg
/// lifted only over a stable triangle, and the last state within the tolerance when `success`.
fn check_plan(m: &QuadrupedModel, cfg: &GaitConfig, start: &GaitState, goal: Point2<f64>, p: &mobil_gait::Plan) {
    assert_eq!(p.steps[0].state, *start);
    assert!(p.steps[0].rule.is_none());
    for (k, w) in p.steps.windows(2).enumerate() {
        let (a, b) = (&w[0].state, &w[1].state);
        let rule = w[1].rule.expect("every later step has a rule");
        assert!(b.in_workspaces(m) && is_supported(cfg.stability_margin - 1e-9, b));
        if let Some(leg) = rule.moving_leg() {
            assert!(
                is_stable(m, cfg.stability_margin, a, leg),
                "leg {leg} lifted off a stable triangle"
            );
        }
        let again = rule.apply(m, cfg, a, goal);
        assert!(
            again.iter().flatten().any(|s| same_state(s, b, 1e-12)),
            "step {} by {rule} is not that rule applied to its parent: {b:?} against {again:?}",
            k + 1
        );
    }
    if p.success {
        assert!(vzd(&p.steps.last().unwrap().state, goal) <= cfg.goal_tolerance);
        assert!(p.failure.is_none());
    }
}

#[test]
fn every_paper_row_gives_a_valid_plan() {
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::paper(cfg.reading);
    for set in [RuleSet::A, RuleSet::B] {
        for e in 1..=3 {
            let start = paper_start(&m, set);
            let eval = Evaluation::try_from(e).unwrap();
            let p = plan(&m, &cfg, &start, GOAL, set, eval, 0, &mut || false);
            assert!(p.success, "{set},({e}): {:?}", p.failure);
            check_plan(&m, &cfg, &start, GOAL, &p);
            // The paper's goal is 14.1 away; a body move covers at most 2·√1.75 = 2.65 on the
            // nominal stance's reach, so at least 6 body moves.
            assert!(p.steps.len() >= 7 && p.expanded as usize >= p.steps.len() - 1);
            assert!(p.generated >= p.expanded);
        }
    }
}

#[test]
fn a_coarse_key_still_gives_an_exact_plan() {
    // With a key of 0.1, states 0.1 apart are one state, and under (3) a cheaper path often
    // reaches a key through a different state than the one first stored under it. The plan must
    // still be exact. On this instance, keeping the state first stored under each key would give
    // a step 37 (leg 0 set nominal, which moves no body) whose body lies 0.025 from its parent's.
    let cfg = GaitConfig {
        key_quantum: 0.1,
        ..GaitConfig::default()
    };
    let m = QuadrupedModel::paper(cfg.reading);
    let start = GaitState::nominal(
        &m,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 1.65,
        },
    );
    let goal = Point2::new(5.0, 3.0);
    let p = plan(
        &m,
        &cfg,
        &start,
        goal,
        RuleSet::A,
        Evaluation::Three,
        20_000,
        &mut || false,
    );
    assert!(p.success, "{:?}", p.failure);
    check_plan(&m, &cfg, &start, goal, &p);
}

/// Records the states the search expands, in order.
struct Recording<'a> {
    inner: GaitProblem<'a>,
    expanded: RefCell<Vec<StateKey>>,
}

impl Problem for Recording<'_> {
    type State = GaitState;
    type Key = StateKey;
    type Step = Rule;
    fn key(&self, s: &GaitState) -> StateKey {
        self.inner.key(s)
    }
    fn is_goal(&self, s: &GaitState) -> bool {
        self.inner.is_goal(s)
    }
    fn start_value(&self, s: &GaitState) -> f64 {
        self.inner.start_value(s)
    }
    fn successors(&self, s: &GaitState, out: &mut Vec<(Rule, GaitState)>) {
        self.expanded.borrow_mut().push(self.inner.key(s));
        self.inner.successors(s, out)
    }
    fn value(&self, p: &GaitState, pf: f64, step: Rule, c: &GaitState) -> f64 {
        self.inner.value(p, pf, step, c)
    }
    fn remaining(&self, s: &GaitState) -> f64 {
        self.inner.remaining(s)
    }
}

#[test]
fn evaluation_2_expands_states_in_the_same_order_as_1() {
    // (2) telescopes to (1) plus the constant h(s0) − h(s0) = 0 (SPEC §7), so both searches must
    // expand the same states in the same order and return the same plan, on every instance.
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::default();
    let instances = [
        (
            RuleSet::A,
            BodyPose {
                x: 0.0,
                y: 0.0,
                phi: PI / 4.0,
            },
            GOAL,
        ),
        (
            RuleSet::A,
            BodyPose {
                x: 1.0,
                y: -2.0,
                phi: 0.3,
            },
            Point2::new(6.0, 4.0),
        ),
        (
            RuleSet::B,
            BodyPose {
                x: 0.0,
                y: 0.0,
                phi: 1.5 * PI,
            },
            GOAL,
        ),
        (
            RuleSet::B,
            BodyPose {
                x: -3.0,
                y: 1.0,
                phi: 2.0,
            },
            Point2::new(2.0, -5.0),
        ),
        (
            RuleSet::A,
            BodyPose {
                x: 0.0,
                y: 0.0,
                phi: PI,
            },
            Point2::new(0.0, 8.0),
        ),
    ];
    for (set, body, goal) in instances {
        let start = GaitState::nominal(&m, body);
        let run = |eval| {
            let rec = Recording {
                inner: GaitProblem {
                    model: &m,
                    cfg: &cfg,
                    goal,
                    set,
                    eval,
                    weights: cfg.weights(set, eval),
                },
                expanded: RefCell::new(Vec::new()),
            };
            let r = search(&rec, start, 20_000, &mut || false);
            let keys: Vec<StateKey> = r.path.iter().map(|n| state_key(&n.state, cfg.key_quantum)).collect();
            (r.end, r.expanded, r.generated, rec.expanded.into_inner(), keys)
        };
        let (one, two) = (run(Evaluation::One), run(Evaluation::Two));
        assert_eq!(one.0, SearchEnd::Goal, "{set} from {body:?}");
        assert_eq!((one.1, one.2), (two.1, two.2), "{set} from {body:?}: counts differ");
        assert!(one.3 == two.3, "{set} from {body:?}: expansion order differs");
        assert_eq!(one.4, two.4, "{set} from {body:?}: plans differ");
    }
}

#[test]
fn a_tiny_expansion_cap_returns_the_best_partial_plan() {
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::default();
    let start = paper_start(&m, RuleSet::B);
    let p = plan(&m, &cfg, &start, GOAL, RuleSet::B, Evaluation::One, 5, &mut || false);
    assert!(!p.success);
    assert_eq!(p.failure, Some(PlanFailure::ExpansionLimit(5)));
    assert!(p.failure.as_ref().unwrap().to_string().contains("EXPANSION_LIMIT"));
    assert_eq!(p.expanded, 5);
    // Partial, yet valid, and nearer the goal than the start (14.14 away).
    check_plan(&m, &cfg, &start, GOAL, &p);
    assert!(p.steps.len() >= 2);
    assert!(vzd(&p.steps.last().unwrap().state, GOAL) < vzd(&start, GOAL));
}

#[test]
fn a_goal_tolerance_no_state_meets_ends_within_the_limit() {
    // With a margin of 0.9 no leg can ever lift (the centre is at most 0.51 inside a lifting
    // triangle once the body has shifted the 0.6 the hull allows), so the robot can only shift
    // and turn on its first footholds: a goal 20 away is unreachable and the state space finite.
    let cfg = GaitConfig {
        stability_margin: 0.9,
        ..GaitConfig::default()
    };
    let m = QuadrupedModel::default();
    let start = GaitState::nominal(&m, BodyPose::default());
    let p = plan(
        &m,
        &cfg,
        &start,
        Point2::new(0.0, 20.0),
        RuleSet::B,
        Evaluation::Three,
        100_000,
        &mut || false,
    );
    assert!(!p.success);
    assert_eq!(p.failure, Some(PlanFailure::NoSuccessor));
    assert!(p.expanded < 100_000);
    assert!(p.leg_moves() == 0);
    // The best partial plan ends at the hull's limit: 1.5 − 0.9 = 0.6 ahead.
    let last = p.steps.last().unwrap().state;
    assert!((last.body.y - 0.6).abs() < 1e-9, "{}", last.body.y);
}

#[test]
fn the_stop_callback_stops_the_search() {
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::default();
    let start = paper_start(&m, RuleSet::B);
    let mut asked = 0;
    let p = plan(&m, &cfg, &start, GOAL, RuleSet::B, Evaluation::One, 0, &mut || {
        asked += 1;
        asked >= 2
    });
    assert!(!p.success);
    assert_eq!(p.failure, Some(PlanFailure::Stopped));
    assert_eq!(asked, 2);
    assert_eq!(p.expanded, 2 * STOP_CHECK_EVERY);
    assert!(p.failure.unwrap().to_string().starts_with("STOPPED"));
}

#[test]
fn invalid_inputs_are_refused_with_a_reason() {
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::default();
    let mut start = GaitState::nominal(&m, BodyPose::default());
    start.feet[2].x += 1.0; // L = 2.5 > 2
    let p = plan(&m, &cfg, &start, GOAL, RuleSet::A, Evaluation::One, 0, &mut || false);
    assert!(!p.success && p.steps.is_empty());
    assert!(p.failure.unwrap().to_string().contains("leg 2"));
    let ok = GaitState::nominal(&m, BodyPose::default());
    let p = plan(
        &m,
        &cfg,
        &ok,
        Point2::new(f64::NAN, 0.0),
        RuleSet::A,
        Evaluation::One,
        0,
        &mut || false,
    );
    assert_eq!(p.failure, Some(PlanFailure::InvalidGoal));
    let bad = GaitConfig {
        goal_tolerance: 0.0,
        ..cfg
    };
    let p = plan(&m, &bad, &ok, GOAL, RuleSet::A, Evaluation::One, 0, &mut || false);
    assert!(p.failure.unwrap().to_string().contains("goal_tolerance"));
}

#[test]
fn a_start_within_the_tolerance_is_its_own_plan() {
    let cfg = GaitConfig::default();
    let m = QuadrupedModel::default();
    let start = GaitState::nominal(&m, BodyPose::default());
    let p = plan(
        &m,
        &cfg,
        &start,
        Point2::new(0.3, 0.0),
        RuleSet::A,
        Evaluation::Three,
        0,
        &mut || false,
    );
    assert!(p.success);
    assert_eq!((p.steps.len(), p.expanded, p.generated), (1, 0, 0));
}

/// A line with states merged on a 0.1 grid, built so that re-parenting meets a state that is a
/// copy of the stored one within the key, not the same state: 0 →a 1.0 →g 2.0 is found first;
/// then 0 →y 7 →x 8 →c 1.02 is a cheaper path to the key of 1.0 (f 0.7 < 1), and from 1.02 the
/// goal's key is reached by g at 2.02 (or, with `drift`, g misses it: 2.12). f is a fixed value
/// per step, so the goal is not re-parented when 1.02 is expanded: its stored link leaves 1.0.
/// With `copy_is_goal`, the goal is (1.01, 1.05) instead: 1.02 is one, 1.0 under its key not.
struct Merged {
    drift: bool,
    copy_is_goal: bool,
}

impl Merged {
    fn apply(&self, step: char, s: f64) -> f64 {
        match step {
            'a' => 1.0,
            'y' => 7.0,
            'x' => 8.0,
            'c' => 1.02,
            _ if self.drift && s != 1.0 => s + 1.1,
            _ => s + 1.0,
        }
    }
}

impl Problem for Merged {
    type State = f64;
    type Key = i64;
    type Step = char;
    fn key(&self, s: &f64) -> i64 {
        (s * 10.0).round() as i64
    }
    fn is_goal(&self, s: &f64) -> bool {
        if self.copy_is_goal {
            *s > 1.01 && *s < 1.05
        } else {
            self.key(s) == 20
        }
    }
    fn start_value(&self, _: &f64) -> f64 {
        0.0
    }
    fn successors(&self, s: &f64, out: &mut Vec<(char, f64)>) {
        let steps: &[char] = match self.key(s) {
            0 => &['a', 'y'],
            70 => &['x'],
            80 => &['c'],
            10 => &['g'],
            _ => &[],
        };
        out.extend(steps.iter().map(|&st| (st, self.apply(st, *s))));
    }
    fn value(&self, _: &f64, _: f64, step: char, _: &f64) -> f64 {
        match step {
            'a' => 1.0,
            'y' => 2.0,
            'x' => 0.5,
            'c' => 0.7,
            _ => 5.0,
        }
    }
    fn remaining(&self, s: &f64) -> f64 {
        (2.0 - s).abs()
    }
}

#[test]
fn re_parenting_within_the_key_keeps_the_path_exact() {
    let p = Merged {
        drift: false,
        copy_is_goal: false,
    };
    let r = search(&p, 0.0, 100, &mut || false);
    assert_eq!(r.end, SearchEnd::Goal);
    let steps: Vec<char> = r.path.iter().skip(1).map(|n| n.step.unwrap()).collect();
    assert_eq!(steps, vec!['y', 'x', 'c', 'g']);
    // Worked out by hand: 0, 7, 8, then c gives 1.02 (not the 1.0 first stored under its key),
    // and g from 1.02 gives 2.02 (not the 2.0 first stored under the goal's key).
    let states: Vec<f64> = r.path.iter().map(|n| n.state).collect();
    assert_eq!(states, vec![0.0, 7.0, 8.0, 1.02, 1.02 + 1.0]);
    for w in r.path.windows(2) {
        assert_eq!(p.apply(w[1].step.unwrap(), w[0].state), w[1].state);
    }
    // With drift, g from 1.02 lands at 2.12, outside the goal's key: the goal stored under it
    // (2.0, reached from 1.0) has no exact path and is not a solution. OPEN then empties. The
    // best partial path is to 2.0 (the nearest to 2), whose last link cannot be made again:
    // it ends at its exact prefix 0, 7, 8, 1.02.
    let p = Merged {
        drift: true,
        copy_is_goal: false,
    };
    let r = search(&p, 0.0, 100, &mut || false);
    assert_eq!(r.end, SearchEnd::OpenEmpty);
    let states: Vec<f64> = r.path.iter().map(|n| n.state).collect();
    assert_eq!(states, vec![0.0, 7.0, 8.0, 1.02]);
    // The copy that re-parenting stores is judged a goal by itself: 1.02 is one, though the 1.0
    // first stored under its key was not. Found when taken from OPEN, before 2.0 (f 0.7 < 5).
    let p = Merged {
        drift: false,
        copy_is_goal: true,
    };
    let r = search(&p, 0.0, 100, &mut || false);
    assert_eq!(r.end, SearchEnd::Goal);
    let states: Vec<f64> = r.path.iter().map(|n| n.state).collect();
    assert_eq!(states, vec![0.0, 7.0, 8.0, 1.02]);
    // Expanded 0, 1.0, 7, 8; generated a, y, g (from 1.0), x, c.
    assert_eq!((r.expanded, r.generated), (4, 5));
    for w in r.path.windows(2) {
        assert_eq!(p.apply(w[1].step.unwrap(), w[0].state), w[1].state);
    }
}

/// Two successors tied on f: which one the search expands first.
struct Fork {
    expanded: RefCell<Vec<u8>>,
    newest: bool,
}

impl Problem for Fork {
    type State = u8;
    type Key = u8;
    type Step = u8;
    fn key(&self, s: &u8) -> u8 {
        *s
    }
    fn is_goal(&self, s: &u8) -> bool {
        *s == 9
    }
    fn start_value(&self, _: &u8) -> f64 {
        0.0
    }
    fn successors(&self, s: &u8, out: &mut Vec<(u8, u8)>) {
        self.expanded.borrow_mut().push(*s);
        // 0 → 1, 2 (in that order), both f = 1; each of 1 and 2 → 9 at f = 2.
        match s {
            0 => out.extend([(1, 1), (2, 2)]),
            1 | 2 => out.push((9, 9)),
            _ => {}
        }
    }
    fn value(&self, _: &u8, parent_f: f64, _: u8, _: &u8) -> f64 {
        parent_f + 1.0
    }
    fn remaining(&self, s: &u8) -> f64 {
        f64::from(9 - s.min(&9))
    }
    fn newest_first(&self) -> bool {
        self.newest
    }
}

#[test]
fn ties_go_to_the_oldest_state_or_with_newest_first_to_the_newest() {
    for (newest, order, path) in [
        (false, vec![0, 1, 2], vec![0, 1, 9]),
        (true, vec![0, 2, 1], vec![0, 2, 9]),
    ] {
        let p = Fork {
            expanded: RefCell::new(Vec::new()),
            newest,
        };
        let r = search(&p, 0, 100, &mut || false);
        // 0, then the tied 1 and 2 (f = 1) before the goal 9 (f = 2): oldest first 1 then 2,
        // newest first 2 then 1. The goal keeps the parent that generated it first (the second
        // path to it is no better).
        assert_eq!(*p.expanded.borrow(), order, "newest first: {newest}");
        let states: Vec<u8> = r.path.iter().map(|n| n.state).collect();
        assert_eq!(states, path, "newest first: {newest}");
    }
    // The gait planner takes the rule from its configuration.
    let cfg = GaitConfig {
        tie_break: mobil_gait::TieBreak::Newest,
        ..GaitConfig::default()
    };
    assert_eq!(
        "newest".parse::<mobil_gait::TieBreak>(),
        Ok(mobil_gait::TieBreak::Newest)
    );
    assert!("lifo".parse::<mobil_gait::TieBreak>().is_err());
    assert_ne!(cfg, GaitConfig::default());
}

#[test]
fn the_planner_takes_the_tie_rule_from_its_configuration() {
    // A,(1) from the paper's start: the search under `newest` is not the search under `oldest`
    // (a planner that ignored the setting would give the same counts and plan).
    let m = QuadrupedModel::default();
    let start = GaitState::nominal(
        &m,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: PI / 4.0,
        },
    );
    let run = |tie_break| {
        let cfg = GaitConfig {
            tie_break,
            ..GaitConfig::default()
        };
        let p = plan(&m, &cfg, &start, GOAL, RuleSet::A, Evaluation::One, 0, &mut || false);
        assert!(p.success, "{:?}", p.failure);
        check_plan(&m, &cfg, &start, GOAL, &p);
        (p.expanded, p.steps.len())
    };
    assert_ne!(run(mobil_gait::TieBreak::Oldest), run(mobil_gait::TieBreak::Newest));
}
