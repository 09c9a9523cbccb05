//! `gait_demo`: the demo's fifth act. Asks a running `gait_node` for the paper's experiment
//! B,(3) on `gait/compute_plan` (from the origin at φ = 3π/2, legs nominal, to (−10, 10)),
//! writes the planned walk as an SVG (the map of the walk and a strip of its leg moves) and
//! prints a one-line summary. The summary and figure are `mobil_tools::gait` (tested
//! there).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use mobil_gait::QuadrupedModel;
use mobil_msgs::mobil_msgs::srv::{PlanGait, PlanGaitRequest, PlanGaitResponse};
use mobil_ros::params::ParamValues;
use mobil_ros::{run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::gait::{figure, summary, GaitWalk, WalkState, DEMO_GOAL, DEMO_START};
use mobil_tools::plot::write_file;
use mobil_tools_node::service_client;
use tracing::info;

fn decl() -> NodeDecl {
    NodeDecl::new(
        "gait_demo",
        "Asks gait_node for a quadruped free-gait plan and draws it",
    )
    .param(ParamSpec::doubles(
        "start",
        &[DEMO_START.0, DEMO_START.1, DEMO_START.2],
        "body start x, y [j], φ [rad]; legs nominal",
    ))
    .param(ParamSpec::doubles("goal", &[DEMO_GOAL.0, DEMO_GOAL.1], "goal x, y [j]"))
    .param(ParamSpec::string("rule_set", "B", "rule set: A or B").choices(&["A", "B"]))
    .param(ParamSpec::integer("evaluation", 3, "evaluation function 1, 2 or 3").within(1.0, 3.0))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/quadruped_gait.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::double("timeout_s", 30.0, "wall time allowed for the answer [s]").above(0.0))
    .check(|p: &ParamValues| {
        match p.f64s("start")?.as_slice() {
            [x, y, phi] if x.is_finite() && y.is_finite() && phi.is_finite() => {}
            _ => return Err("start must be three finite numbers [x, y, φ]".into()),
        }
        match p.f64s("goal")?.as_slice() {
            [x, y] if x.is_finite() && y.is_finite() => Ok(()),
            _ => Err("goal must be two finite numbers [x, y]".into()),
        }
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

/// Calls `gait/compute_plan`, re-sending each 3 s (a request sent before discovery matched is
/// lost) until `deadline`: the last attempt gets only the time left.
async fn call(node: &mut RosNode, request: PlanGaitRequest, deadline: Instant) -> anyhow::Result<PlanGaitResponse> {
    let client = service_client::<PlanGait>(node, "gait/compute_plan")?;
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    // Matched before the first call, so that it is not lost to discovery (ROS2-NOTES).
    let left = deadline.saturating_duration_since(Instant::now());
    tokio::select! {
        _ = &mut shutdown => anyhow::bail!("interrupted"),
        matched = tokio::time::timeout(left, client.wait_for_service(node.inner())) => {
            if matched.is_err() {
                anyhow::bail!("gait/compute_plan not found (is gait_node running on this ROS_DOMAIN_ID?)");
            }
        }
    }
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            anyhow::bail!("gait/compute_plan did not answer (is gait_node running on this ROS_DOMAIN_ID?)");
        }
        let attempt = Duration::from_secs(3).min(left);
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            answer = tokio::time::timeout(attempt, client.async_call_service(request.clone())) => {
                match answer {
                    Ok(Ok(reply)) => return Ok(reply),
                    Ok(Err(e)) => info!("gait/compute_plan call failed ({e:?}); asking again"),
                    Err(_) => info!("no answer within {:.1} s; asking again", attempt.as_secs_f64()),
                }
            }
        }
    }
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let start = p.f64s("start").map_err(map_err)?;
    let goal = p.f64s("goal").map_err(map_err)?;
    let (x, y, phi, gx, gy) = match (start.as_slice(), goal.as_slice()) {
        (&[x, y, phi], &[gx, gy]) => (x, y, phi, gx, gy),
        _ => anyhow::bail!("start needs [x, y, φ] and goal [x, y]"),
    };
    let rule_set = p.string("rule_set").map_err(map_err)?;
    let evaluation = u8::try_from(p.i64("evaluation").map_err(map_err)?)?;
    let output = p.string("output_svg").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    let mut request = PlanGaitRequest::default();
    (request.start.x, request.start.y, request.start.theta) = (x, y, phi);
    (request.goal.x, request.goal.y) = (gx, gy);
    request.rule_set = rule_set.clone();
    request.evaluation = evaluation;
    let began = Instant::now();
    let reply = call(node, request, began + timeout).await?;
    let call_s = began.elapsed().as_secs_f64();
    let plan = reply.plan;
    let model = QuadrupedModel::default();
    let walk = GaitWalk {
        rule_set: plan.rule_set.clone(),
        evaluation: plan.evaluation,
        goal: (gx, gy),
        success: plan.success,
        reason: plan.reason.clone(),
        expanded: plan.states_expanded,
        generated: plan.states_generated,
        steps: plan
            .steps
            .iter()
            .map(|s| WalkState {
                body: (s.body.x, s.body.y, s.body.theta),
                feet: s.feet.clone().map(|f| (f.x, f.y)),
                moving_leg: s.moving_leg,
                rule: s.rule_name.clone(),
            })
            .collect(),
        call_s,
        body_size: (model.a, model.b),
    };
    let title = format!(
        "gait_node: quadruped free gait, rule set {rule_set}, evaluation ({evaluation}), ({x}, {y}, φ {:.0}°) → ({gx}, {gy})",
        phi.to_degrees()
    );
    write_file(&output, &figure(&walk, &title)).map_err(|e| anyhow::anyhow!("cannot write {output}: {e}"))?;
    println!("{}", summary(&walk, &output));
    if !walk.success {
        anyhow::bail!("no plan: {}", walk.reason);
    }
    Ok(())
}
