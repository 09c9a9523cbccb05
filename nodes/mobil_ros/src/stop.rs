//! The last command of a motion node: published, then waited for (bounded) before the node
//! leaves the DDS domain.
//!
//! On shutdown or failure a node that commands motion publishes its zero command with
//! [`final_stop`], which returns once every matched reliable reader has acknowledged it, or
//! after [`FINAL_STOP_WAIT`]; the node then shuts down. Dropping the writer right after
//! `publish` could lose the sample, and the drivers would keep the previous command until their
//! own timeout.
//!
//! ```no_run
//! # async fn demo(node: &mut mobil_ros::RosNode) -> anyhow::Result<()> {
//! use mobil_msgs::geometry_msgs::msg::Twist;
//! use mobil_ros::stop::{final_stop, FINAL_STOP_WAIT};
//! let cmd = node.publisher::<Twist>("cmd_vel", &mobil_ros::qos::default_qos())?;
//! let result: anyhow::Result<()> = async { /* the node's loop */ Ok(()) }.await;
//! final_stop(&cmd, Twist::default(), FINAL_STOP_WAIT).await; // on success and failure alike
//! result
//! # }
//! ```

use mobil_msgs::geometry_msgs::msg::Twist;
use ros2_client::Publisher;
use serde::Serialize;
use std::time::{Duration, Instant};
use tracing::warn;

/// How long [`final_stop`] waits by default for the readers' acknowledgements.
pub const FINAL_STOP_WAIT: Duration = Duration::from_millis(500);

/// How the final command went out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FinalStop {
    /// Every matched reliable reader acknowledged it (or none was matched).
    Acknowledged,
    /// Some reader had not acknowledged it when the wait ended.
    TimedOut,
    /// It could not be published.
    Failed(String),
}

/// Publishes `stop` and waits until every matched reliable reader has acknowledged it, at most
/// `max_wait`; logs a warning unless it was acknowledged. Never blocks the event loop.
pub async fn final_stop<M: Serialize + std::fmt::Debug>(
    publisher: &Publisher<M>,
    stop: M,
    max_wait: Duration,
) -> FinalStop {
    let outcome = publish_and_wait(publisher, stop, max_wait).await;
    match &outcome {
        FinalStop::Acknowledged => {}
        FinalStop::TimedOut => warn!("final stop command not acknowledged within {max_wait:?}"),
        FinalStop::Failed(e) => warn!("cannot publish the final stop command: {e}"),
    }
    outcome
}

async fn publish_and_wait<M: Serialize + std::fmt::Debug>(
    publisher: &Publisher<M>,
    stop: M,
    max_wait: Duration,
) -> FinalStop {
    if let Err(e) = publisher.publish(stop) {
        return FinalStop::Failed(format!("{e:?}"));
    }
    // A zero wait only checks, so the event loop is never blocked.
    wait_for(
        || {
            publisher
                .wait_for_acknowledgments(Duration::ZERO)
                .map_err(|e| format!("{e:?}"))
        },
        max_wait,
    )
    .await
}

/// Polls `acknowledged` every 2 ms until it says yes, fails, or `max_wait` has passed since the
/// call (checked once more at the deadline, so a zero wait is one check).
async fn wait_for(mut acknowledged: impl FnMut() -> Result<bool, String>, max_wait: Duration) -> FinalStop {
    let deadline = Instant::now() + max_wait;
    loop {
        match acknowledged() {
            Ok(true) => return FinalStop::Acknowledged,
            Ok(false) if Instant::now() >= deadline => return FinalStop::TimedOut,
            Ok(false) => tokio::time::sleep(Duration::from_millis(2)).await,
            Err(e) => return FinalStop::Failed(e),
        }
    }
}

/// Whether the robot is (as far as this node commanded it) moving: a refused input stops it
/// with one zero command, not one per refusal.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CommandGate {
    moving: bool,
}

impl CommandGate {
    /// A command went out (zero or not).
    pub fn sent(&mut self, twist: &Twist) {
        let t = twist;
        self.moving = [
            t.linear.x,
            t.linear.y,
            t.linear.z,
            t.angular.x,
            t.angular.y,
            t.angular.z,
        ]
        .iter()
        .any(|v| *v != 0.0);
    }

    /// An input was refused while a goal runs: `true` when a zero command must go out now (the
    /// last command moved the robot); the gate then counts the robot as stopped.
    pub fn refused(&mut self) -> bool {
        std::mem::take(&mut self.moving)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn the_wait_ends_on_the_acknowledgement_or_the_deadline() {
        // Acknowledged on the third check: no earlier, no deadline reached.
        let mut checks = 0;
        let outcome = wait_for(
            || {
                checks += 1;
                Ok(checks == 3)
            },
            Duration::from_secs(60),
        )
        .await;
        assert_eq!((outcome, checks), (FinalStop::Acknowledged, 3));

        // Never acknowledged: TimedOut, never before the deadline (it returns at all: the wait
        // is bounded).
        let started = Instant::now();
        let outcome = wait_for(|| Ok(false), Duration::from_millis(30)).await;
        assert_eq!(outcome, FinalStop::TimedOut);
        assert!(started.elapsed() >= Duration::from_millis(30));

        // A zero wait is one check.
        let mut checks = 0;
        let outcome = wait_for(
            || {
                checks += 1;
                Ok(false)
            },
            Duration::ZERO,
        )
        .await;
        assert_eq!((outcome, checks), (FinalStop::TimedOut, 1));

        // A failing check ends the wait with its error.
        let outcome = wait_for(|| Err("writer gone".into()), Duration::from_secs(60)).await;
        assert_eq!(outcome, FinalStop::Failed("writer gone".into()));
    }

    #[test]
    fn a_refusal_stops_a_moving_robot_once() {
        let mut g = CommandGate::default();
        // Nothing commanded yet: no zero needed.
        assert!(!g.refused());
        let mut moving = Twist::default();
        moving.angular.z = 0.3;
        g.sent(&moving);
        assert!(g.refused());
        // The zero went out: a second refusal in a row sends none.
        assert!(!g.refused());
        g.sent(&moving);
        g.sent(&Twist::default());
        assert!(!g.refused());
    }
}
