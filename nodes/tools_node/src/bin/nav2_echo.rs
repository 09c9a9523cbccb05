//! `nav2_echo`: serves Nav2's Jazzy actions `navigate_to_pose`, `dock_robot`, `undock_robot` and
//! `follow_waypoints` and answers every goal at once with a result computed from the goal, so a
//! Nav2 client (rclpy, rclcpp, the Nav2 tools) can check the whole wire round trip. A test
//! fixture for the vendored `nav2_msgs` types, not a navigator: the robot does not move.
//!
//! Results (SUCCEEDED, after one feedback message):
//! - NavigateToPose: `error_msg` = "FRAME X Y BEHAVIOR_TREE" (the goal pose's frame and position);
//! - DockRobot: `success` = `use_dock_id`, `num_retries` = `max_staging_time` (whole seconds),
//!   `error_msg` = "DOCK_ID/DOCK_TYPE";
//! - UndockRobot: `error_code` = `max_undocking_time` (whole seconds), `error_msg` = `dock_type`;
//! - FollowWaypoints: every pose with x < 0 is a missed waypoint (TASK_EXECUTOR_FAILED), and then
//!   `error_code` = UNKNOWN; `error_msg` = "MISSED of N missed, LOOPS loops from GOAL_INDEX".

use mobil_msgs::nav2_msgs::action::{
    DockRobot, DockRobotFeedback, DockRobotGoal, DockRobotResult, FollowWaypoints, FollowWaypointsFeedback,
    FollowWaypointsGoal, FollowWaypointsResult, NavigateToPose, NavigateToPoseFeedback, NavigateToPoseGoal,
    NavigateToPoseResult, UndockRobot, UndockRobotFeedback, UndockRobotGoal, UndockRobotResult,
};
use mobil_msgs::nav2_msgs::msg::MissedWaypoint;
use mobil_msgs::RosAction;
use mobil_ros::action::{ActionEvent, GoalEnd, GoalServer, GoalServerConfig};
use mobil_ros::{run_node, shutdown_signal, NodeDecl, RosNode};
use std::process::ExitCode;
use tracing::{info, warn};

fn main() -> ExitCode {
    run_node(
        &NodeDecl::new(
            "nav2_echo",
            "Answers goals of Nav2's NavigateToPose, DockRobot, UndockRobot and FollowWaypoints with results computed from them (a test fixture)",
        ),
        |node| Box::pin(serve(node)),
    )
}

fn navigate(goal: &NavigateToPoseGoal) -> (NavigateToPoseFeedback, NavigateToPoseResult) {
    let p = &goal.pose;
    let feedback = NavigateToPoseFeedback {
        current_pose: p.clone(),
        distance_remaining: p.pose.position.x.hypot(p.pose.position.y) as f32,
        ..Default::default()
    };
    let result = NavigateToPoseResult {
        error_code: NavigateToPoseResult::NONE,
        error_msg: format!(
            "{} {} {} {}",
            p.header.frame_id, p.pose.position.x, p.pose.position.y, goal.behavior_tree
        ),
    };
    (feedback, result)
}

fn dock(goal: &DockRobotGoal) -> (DockRobotFeedback, DockRobotResult) {
    let feedback = DockRobotFeedback {
        state: DockRobotFeedback::CONTROLLING,
        ..Default::default()
    };
    let result = DockRobotResult {
        success: goal.use_dock_id,
        error_code: DockRobotResult::NONE,
        // Saturating: a test fixture's echo of a float as a count.
        num_retries: goal.max_staging_time as u16,
        error_msg: format!("{}/{}", goal.dock_id, goal.dock_type),
    };
    (feedback, result)
}

fn undock(goal: &UndockRobotGoal) -> (UndockRobotFeedback, UndockRobotResult) {
    let result = UndockRobotResult {
        success: true,
        error_code: goal.max_undocking_time as u16,
        error_msg: goal.dock_type.clone(),
    };
    (UndockRobotFeedback::default(), result)
}

fn follow(goal: &FollowWaypointsGoal) -> (FollowWaypointsFeedback, FollowWaypointsResult) {
    let missed: Vec<MissedWaypoint> = goal
        .poses
        .iter()
        .enumerate()
        .filter(|(_, p)| p.pose.position.x < 0.0)
        .map(|(i, p)| MissedWaypoint {
            index: i as u32,
            goal: p.clone(),
            error_code: FollowWaypointsResult::TASK_EXECUTOR_FAILED,
        })
        .collect();
    let result = FollowWaypointsResult {
        error_code: if missed.is_empty() {
            FollowWaypointsResult::NONE
        } else {
            FollowWaypointsResult::UNKNOWN
        },
        error_msg: format!(
            "{} of {} missed, {} loops from {}",
            missed.len(),
            goal.poses.len(),
            goal.number_of_loops,
            goal.goal_index
        ),
        missed_waypoints: missed,
    };
    let feedback = FollowWaypointsFeedback {
        current_waypoint: goal.goal_index,
    };
    (feedback, result)
}

/// What a goal gets: its one feedback message and its result.
type Response<A> = (<A as RosAction>::Feedback, <A as RosAction>::Result);

/// Accepts a goal, sends one feedback and the result.
async fn answer<A: RosAction + 'static>(
    server: &mut GoalServer<A>,
    event: ActionEvent<A::Goal>,
    respond: fn(&A::Goal) -> Response<A>,
    now_nanos: i64,
) -> anyhow::Result<()> {
    let ActionEvent::Goal(request) = event else {
        // Goals end as soon as they are accepted; nothing is left to cancel.
        return Ok(());
    };
    let (feedback, result) = respond(request.goal());
    info!("{}: goal {:?}", A::NAME, request.id());
    server.accept(request, |_| A::Result::default(), now_nanos).await?;
    if let Err(e) = server.feedback(feedback).await {
        warn!("{}: {e}", A::NAME);
    }
    server.finish(GoalEnd::Succeeded, result);
    Ok(())
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config = GoalServerConfig::default();
    let mut navigate_s = GoalServer::<NavigateToPose>::create(node, "navigate_to_pose", config.clone())?;
    let mut dock_s = GoalServer::<DockRobot>::create(node, "dock_robot", config.clone())?;
    let mut undock_s = GoalServer::<UndockRobot>::create(node, "undock_robot", config.clone())?;
    let mut follow_s = GoalServer::<FollowWaypoints>::create(node, "follow_waypoints", config)?;
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    info!("serving navigate_to_pose, dock_robot, undock_robot, follow_waypoints");
    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            e = navigate_s.next_event() => answer(&mut navigate_s, e, navigate, node.now_nanos()).await?,
            e = dock_s.next_event() => answer(&mut dock_s, e, dock, node.now_nanos()).await?,
            e = undock_s.next_event() => answer(&mut undock_s, e, undock, node.now_nanos()).await?,
            e = follow_s.next_event() => answer(&mut follow_s, e, follow, node.now_nanos()).await?,
        }
    }
    // Closed together: each may wait for its clients (GoalServer::close).
    tokio::join!(
        navigate_s.close(NavigateToPoseResult::default()),
        dock_s.close(DockRobotResult::default()),
        undock_s.close(UndockRobotResult::default()),
        follow_s.close(FollowWaypointsResult::default()),
    );
    Ok(())
}
