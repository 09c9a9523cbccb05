//! `terrain_node`: terrain irregularity of a hexapod from where its feet landed (SPEC §6), the
//! shell of [`mobil_terrain`]. Each `terrain/touchdown` (reliable, depth 10: a touchdown is an
//! event, none may be lost) updates that leg's foot; once all six are known, every touchdown
//! gives an assessment on `terrain/assessment` (latched) and the planes on `terrain/markers`.
//! A refused touchdown or an unassessable stance is logged (rate-limited), counted, and the last
//! good assessment is published again with the new counts. The rules are in the crate docs.

use mobil_msgs::mobil_msgs::msg::{FootTouchdown, TerrainAssessment};
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use mobil_ros::input::Inputs;
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode};
use mobil_terrain_node::{assessment_message, markers, TerrainNodeConfig, TerrainState, TouchdownOutcome};
use ros2_client::Publisher;
use std::process::ExitCode;
use std::time::Duration;
use tracing::{info, warn};

fn decl() -> NodeDecl {
    NodeDecl::for_config::<TerrainNodeConfig>(
        "terrain",
        "Hexapod terrain assessment from the feet: terrain/touchdown in, terrain/assessment (σ, plane \
         angles, class, advised gait) and terrain/markers out",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

struct Outputs {
    assessment: Publisher<TerrainAssessment>,
    markers: Publisher<MarkerArray>,
}

struct Shell {
    state: TerrainState,
    throttle: LogThrottle,
    first_assessment: bool,
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: TerrainNodeConfig = node.config()?;
    let out = Outputs {
        assessment: node.publisher::<TerrainAssessment>("terrain/assessment", &qos::latched())?,
        markers: node.publisher::<MarkerArray>("terrain/markers", &qos::default_qos())?,
    };
    let sub = node.subscription::<FootTouchdown>("terrain/touchdown", &qos::reliable(10))?;
    let mut shell = Shell {
        state: TerrainState::new(config.terrain)?,
        throttle: LogThrottle::new(Duration::from_secs(2)),
        first_assessment: true,
    };
    info!(
        "waiting for touchdowns on terrain/touchdown (frame `{}`)",
        shell.state.config().body_frame
    );
    // An undecodable touchdown is logged (rate-limited) by the inputs and not counted: the
    // counter is of touchdowns the node could read and refused.
    let mut inputs = Inputs::new();
    inputs.add(
        sub.async_stream(),
        "terrain/touchdown",
        "touchdown ignored",
        |m: FootTouchdown| m,
    );
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    loop {
        tokio::select! {
            _ = &mut shutdown => return Ok(()),
            Some(changed) = node.config_changed::<TerrainNodeConfig>() => match changed {
                Ok(c) => match shell.state.reconfigure(c.terrain) {
                    Ok(Some(_)) => {
                        info!("parameters changed: the stored feet assessed again");
                        shell.publish_last(&out);
                    }
                    Ok(None) => info!("parameters changed"),
                    Err(e) => warn!("parameters not applied: {e}"),
                },
                Err(e) => warn!("parameters not applied: {e}"),
            },
            m = inputs.next() => shell.touchdown(&out, &m?),
        }
    }
}

impl Shell {
    fn touchdown(&mut self, out: &Outputs, m: &FootTouchdown) {
        let (outcome, backwards) = self.state.touchdown(m);
        if backwards {
            warn_throttled!(
                self.throttle,
                "backwards",
                "touchdown of {} stamped before that leg's previous one: the sender's clock went back; accepted",
                m.leg
            );
        }
        match outcome {
            TouchdownOutcome::Assessed(a) => {
                let msg = assessment_message(
                    &a,
                    m.header.stamp.clone(),
                    &self.state.config().body_frame,
                    self.state.rejected_touchdowns(),
                    self.state.failed_assessments(),
                );
                if self.first_assessment {
                    info!(
                        "first assessment: σ {:.4} m, α12 {:.2}°, {} ({})",
                        a.sigma,
                        a.alpha12.to_degrees(),
                        a.class.name(),
                        a.advice.name()
                    );
                    self.first_assessment = false;
                }
                if let Err(e) = out.assessment.publish(msg) {
                    warn_throttled!(self.throttle, "publish", "cannot publish terrain/assessment: {e:?}");
                }
                let body = self.state.config().body_points();
                let array = markers(&a, &body, m.header.stamp.clone(), &self.state.config().body_frame);
                if let Err(e) = out.markers.publish(array) {
                    warn_throttled!(self.throttle, "markers", "cannot publish terrain/markers: {e:?}");
                }
            }
            TouchdownOutcome::Waiting(n) => {
                if n == 1 {
                    info!(
                        "first touchdown ({}); assessing once all six legs have touched down",
                        m.leg
                    );
                }
            }
            TouchdownOutcome::Refused(r) => {
                warn_throttled!(
                    self.throttle,
                    "refused",
                    "touchdown dropped: {r} ({} refused so far)",
                    self.state.rejected_touchdowns()
                );
                self.publish_last(out);
            }
            TouchdownOutcome::Failed(e) => {
                warn_throttled!(
                    self.throttle,
                    "failed",
                    "stance not assessed: {e}; the last assessment stays ({} so far)",
                    self.state.failed_assessments()
                );
                self.publish_last(out);
            }
        }
    }

    /// The last good assessment again, with the current counts (nothing before the first).
    fn publish_last(&mut self, out: &Outputs) {
        if let Some(msg) = self.state.last_message()
            && let Err(e) = out.assessment.publish(msg)
        {
            warn_throttled!(self.throttle, "publish", "cannot publish terrain/assessment: {e:?}");
        }
    }
}
