//! `GoalServer` against ros2-client's own action client, two DDS participants in one process:
//! reject, accept, feedback, pre-emption (the old goal ends ABORTED with the result built from
//! it), cancel (CANCELED), results kept and asked for again, and the answers for ids the server
//! does not know (rcl_action's; the wire-level comparison with rclpy is tests/test_action_protocol.py).

use futures::StreamExt;
use mobil_msgs::mobil_msgs::action::{DriveDistance, DriveDistanceFeedback, DriveDistanceGoal, DriveDistanceResult};
use mobil_msgs::RosAction;
use mobil_ros::action::{ActionEvent, GoalEnd, GoalServer, GoalServerConfig};
use ros2_client::action::{ActionClient, ActionClientQosPolicies, GoalStatusEnum};
use ros2_client::action_msgs::CancelGoalResponseEnum;
use ros2_client::builtin_interfaces::Time;
use ros2_client::{Context, ContextOptions, Name, NodeName, NodeOptions, ServiceMapping};
use std::time::Duration;

type Client = ActionClient<DriveDistanceGoal, DriveDistanceResult, DriveDistanceFeedback>;

fn goal(distance: f64) -> DriveDistanceGoal {
    DriveDistanceGoal { distance, speed: 0.2 }
}

/// The server side: rejects goals with a distance ≤ 0; a pre-empted goal's result is its own
/// distance (so the test sees which goal the closure got); a canceled goal's result is half of
/// its distance, except a goal of distance 5, whose cancel it never acts on (it stays CANCELING);
/// the active goal gets a feedback of (0.25, distance − 0.25) every 50 ms. It panics (ending its task)
/// if a cancel is reported for anything but the active goal, or twice for one goal.
async fn serve(mut server: GoalServer<DriveDistance>) {
    let mut reported = Vec::new();
    let mut ticker = tokio::time::interval(Duration::from_millis(50));
    loop {
        let event = tokio::select! {
            event = server.next_event() => event,
            _ = ticker.tick() => {
                if let Some(distance) = server.active_goal().map(|g| g.distance) {
                    server
                        .feedback(DriveDistanceFeedback { travelled: 0.25, remaining: distance - 0.25 })
                        .await
                        .unwrap();
                }
                continue;
            }
        };
        match event {
            ActionEvent::Goal(request) if request.goal().distance <= 0.0 => {
                server.reject(request, "distance must be above zero").await;
            }
            ActionEvent::Goal(request) => {
                let preempted = |old: &DriveDistanceGoal| DriveDistanceResult {
                    travelled: old.distance,
                    reason: "preempted by a newer goal".into(),
                };
                server.accept(request, preempted, Time::now().to_nanos()).await.unwrap();
            }
            ActionEvent::CancelRequested(id) => {
                assert_eq!(server.active_id(), Some(id));
                assert!(!reported.contains(&id), "cancel of {id:?} reported twice");
                reported.push(id);
                assert!(server.is_canceling());
                let distance = server.active_goal().map(|g| g.distance).unwrap();
                if distance == 5.0 {
                    continue;
                }
                let half = distance / 2.0;
                server.finish(
                    GoalEnd::Canceled,
                    DriveDistanceResult {
                        travelled: half,
                        reason: "canceled".into(),
                    },
                );
            }
        }
    }
}

/// Awaits `f` for at most 10 s; the reply must be a success.
async fn within<T, E: std::fmt::Debug>(f: impl std::future::Future<Output = Result<T, E>>) -> T {
    tokio::time::timeout(Duration::from_secs(10), f)
        .await
        .expect("no reply within 10 s")
        .expect("the call failed")
}

/// Sends a goal until a response arrives. ros2-client's client writes its first request at once,
/// before discovery may have matched the server's request reader, and that request is lost
/// (measured here: the first goal usually needs a second attempt); only a reply proves the path
/// works.
async fn send(client: &Client, g: DriveDistanceGoal) -> (ros2_client::action::GoalId, bool) {
    for _ in 0..5 {
        if let Ok(Ok((id, response))) =
            tokio::time::timeout(Duration::from_secs(3), client.async_send_goal(g.clone())).await
        {
            return (id, response.accepted);
        }
    }
    panic!("no goal response in 5 attempts");
}

/// A server on `action` (spawned, running [`serve`]) and a client of it, in two DDS participants
/// of a domain of this test process's own (the Python tests use 100..199); the contexts are
/// returned to be kept alive.
fn start(action: &str, config: GoalServerConfig) -> (Client, tokio::task::JoinHandle<()>, (Context, Context)) {
    let domain = 200 + (std::process::id() % 30) as u16;
    let name = Name::new("/", action).unwrap();

    let server_context = Context::with_options(ContextOptions::new().domain_id(domain)).unwrap();
    let mut server_node = server_context
        .new_node(
            NodeName::new("/", &format!("{action}_server")).unwrap(),
            NodeOptions::new(),
        )
        .unwrap();
    let server = GoalServer::<DriveDistance>::on_node(&mut server_node, &name, config).unwrap();
    let serving = tokio::spawn(serve(server));

    let client_context = Context::with_options(ContextOptions::new().domain_id(domain)).unwrap();
    let mut client_node = client_context
        .new_node(
            NodeName::new("/", &format!("{action}_client")).unwrap(),
            NodeOptions::new(),
        )
        .unwrap();
    let service = mobil_ros::qos::reliable(10);
    let client: Client = client_node
        .create_action_client(
            ServiceMapping::Enhanced,
            &name,
            &DriveDistance::type_name(),
            ActionClientQosPolicies {
                goal_service: service.clone(),
                result_service: service.clone(),
                cancel_service: service.clone(),
                feedback_subscription: service,
                status_subscription: mobil_ros::qos::latched(),
            },
        )
        .unwrap();
    (client, serving, (server_context, client_context))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn reject_accept_feedback_preempt_cancel_and_results() {
    let (client, serving, _contexts) = start("drive_test", GoalServerConfig::default());

    // Rejected: the server refuses a negative distance.
    let (_, accepted) = send(&client, goal(-1.0)).await;
    assert!(!accepted);

    // Accepted, with feedback.
    let (first, accepted) = send(&client, goal(1.5)).await;
    assert!(accepted);
    // Feedback published before the client's feedback reader is matched is lost; the server
    // publishes it every 50 ms, so one arrives once the reader is matched.
    let stream = client.feedback_stream(first);
    futures::pin_mut!(stream);
    let f = tokio::time::timeout(Duration::from_secs(5), stream.next())
        .await
        .expect("no feedback within 5 s")
        .expect("the feedback stream ended")
        .expect("undecodable feedback");
    assert_eq!((f.travelled, f.remaining), (0.25, 1.25));

    // A second goal pre-empts the first: ABORTED, with the result the closure built from the
    // FIRST goal (its distance, 1.5).
    let (second, accepted) = send(&client, goal(3.0)).await;
    assert!(accepted);
    let (status, result) = within(client.async_request_result(first)).await;
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(result.travelled, 1.5);
    assert_eq!(result.reason, "preempted by a newer goal");

    // Canceling the second: CANCELED, half of its 3.0.
    let cancel = within(client.async_cancel_goal(second, Time::ZERO)).await;
    assert_eq!(cancel.goals_canceling.len(), 1);
    assert_eq!(cancel.goals_canceling[0].goal_id, second);
    let (status, result) = within(client.async_request_result(second)).await;
    assert_eq!(status, GoalStatusEnum::Canceled);
    assert_eq!((result.travelled, result.reason.as_str()), (1.5, "canceled"));

    // Its result is kept: asked again, the same answer.
    let (status, result) = within(client.async_request_result(second)).await;
    assert_eq!((status, result.travelled), (GoalStatusEnum::Canceled, 1.5));
    // Nothing is active now: a cancel of the finished goal is refused as rcl_action refuses it
    // (ERROR_GOAL_TERMINATED), and one of an id never seen as unknown.
    let cancel = within(client.async_cancel_goal(second, Time::ZERO)).await;
    assert!(cancel.goals_canceling.is_empty());
    assert_eq!(cancel.return_code, CancelGoalResponseEnum::GoalTerminated);
    let unknown = ros2_client::action::GoalId::new_random();
    let cancel = within(client.async_cancel_goal(unknown, Time::ZERO)).await;
    assert_eq!(cancel.return_code, CancelGoalResponseEnum::UnknownGoal);
    // A result for an id never seen: STATUS_UNKNOWN with a default result, at once.
    let asked = std::time::Instant::now();
    let (status, result) = within(client.async_request_result(unknown)).await;
    assert_eq!(
        (status, result.travelled, result.reason.as_str()),
        (GoalStatusEnum::Unknown, 0.0, "")
    );
    assert!(
        asked.elapsed() < Duration::from_secs(2),
        "answered in {:?}",
        asked.elapsed()
    );

    // A goal the server is slow to cancel (distance 5): canceled once (agreed, the goal listed),
    // then again while it is CANCELING, which is refused as rcl_action refuses a goal that cannot
    // move to CANCELING (ERROR_GOAL_TERMINATED), and not reported to the node a second time
    // (`serve` would panic).
    let (third, accepted) = send(&client, goal(5.0)).await;
    assert!(accepted);
    let cancel = within(client.async_cancel_goal(third, Time::ZERO)).await;
    assert_eq!(cancel.return_code, CancelGoalResponseEnum::None);
    assert_eq!(cancel.goals_canceling.len(), 1);
    assert_eq!(cancel.goals_canceling[0].goal_id, third);
    let again = within(client.async_cancel_goal(third, Time::ZERO)).await;
    assert_eq!(again.return_code, CancelGoalResponseEnum::GoalTerminated);
    assert!(again.goals_canceling.is_empty());
    // Pre-empted while CANCELING, it ends CANCELED with the result built from it (5.0).
    let (_, accepted) = send(&client, goal(1.0)).await;
    assert!(accepted);
    let (status, result) = within(client.async_request_result(third)).await;
    assert_eq!(status, GoalStatusEnum::Canceled);
    assert_eq!(
        (result.travelled, result.reason.as_str()),
        (5.0, "preempted by a newer goal")
    );

    assert!(!serving.is_finished(), "the server task panicked");
    serving.abort();
}

/// Goal 1 is pre-empted by goal 2 and its client never asks for goal 1's result; goal 2 is then
/// canceled and its result asked for. With results delivered one after another, goal 2's would
/// wait behind goal 1's for the 10 s `result_timeout`; delivered concurrently, it comes as soon as
/// it is asked for (a reply round trip in one process: well under 2 s).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unasked_result_does_not_hold_up_the_next() {
    let timeout = Duration::from_secs(10);
    let (client, serving, _contexts) = start(
        "drive_test_unasked",
        GoalServerConfig {
            result_timeout: timeout,
        },
    );

    let (first, accepted) = send(&client, goal(1.0)).await;
    assert!(accepted);
    let (second, accepted) = send(&client, goal(2.0)).await;
    assert!(accepted);
    assert_ne!(first, second);
    // Goal 1 is now ABORTED, its result queued; nobody asks for it.
    let cancel = within(client.async_cancel_goal(second, Time::ZERO)).await;
    assert_eq!(cancel.goals_canceling.len(), 1);

    let asked = std::time::Instant::now();
    let (status, result) = within(client.async_request_result(second)).await;
    let waited = asked.elapsed();
    assert_eq!(status, GoalStatusEnum::Canceled);
    assert_eq!((result.travelled, result.reason.as_str()), (1.0, "canceled"));
    assert!(
        waited < Duration::from_secs(2),
        "goal 2's result took {waited:?}: held up behind goal 1's"
    );
    serving.abort();
}
