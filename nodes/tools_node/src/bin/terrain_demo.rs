//! `terrain_demo`: the demo's fourth act. Records `terrain/assessment` while `hexapod_sim` walks
//! the course flat → slope → rough and `terrain_node` assesses its touchdowns, until an
//! assessment is stamped `walk_s` simulated seconds or later; then writes an SVG of σ, α12 and
//! α13 over the walk on a background coloured by class, with the thresholds as lines and the
//! advised gait as a strip, and prints a one-line summary. The record, summary and figure are
//! `mobil_tools::terrain` (tested there).

use futures::StreamExt;
use mobil_msgs::mobil_msgs::msg::TerrainAssessment;
use mobil_ros::time::secs_from_stamp;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_terrain::TerrainConfig;
use mobil_tools::plot::write_file;
use mobil_tools::terrain::{figure, push_new, summary, title, Sample};
use std::process::ExitCode;
use std::time::{Duration, Instant};

fn decl() -> NodeDecl {
    NodeDecl::new(
        "terrain_demo",
        "Records terrain/assessment over a hexapod's walk and plots σ, α12, α13, class and gait",
    )
    .param(ParamSpec::double("walk_s", 40.0, "stop at the first assessment stamped this late [s]").above(0.0))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/hexapod_terrain.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::double("timeout_s", 60.0, "wall time allowed for the whole run [s]").above(0.0))
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let walk_s = p.f64("walk_s").map_err(map_err)?;
    let out = p.string("output_svg").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    // Every assessment: depth 100 matches the latched writer and keeps a tripod's burst.
    let sub = node.subscription::<TerrainAssessment>(
        "terrain/assessment",
        &qos::reliable(100).durability(ros2_client::qos::Durability::TransientLocal),
    )?;
    let stream = sub.async_stream();
    let shutdown = shutdown_signal();
    let deadline = tokio::time::sleep(timeout);
    tokio::pin!(stream, shutdown, deadline);
    let started = Instant::now();
    let mut samples: Vec<Sample> = Vec::new();
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = &mut deadline => anyhow::bail!(
                "no assessment stamped {walk_s} s within {timeout:?} ({} recorded; are hexapod_sim and terrain_node running on this ROS_DOMAIN_ID?)",
                samples.len()
            ),
            Some(m) = stream.next() => {
                let Ok((a, _)) = m else { continue };
                let Some(t) = secs_from_stamp(&a.header.stamp) else { continue };
                let sample = Sample {
                    t,
                    sigma: a.sigma,
                    alpha12: a.alpha12,
                    alpha13: a.alpha13,
                    class: a.terrain_class,
                    gait: a.advised_gait,
                };
                if !push_new(&mut samples, sample) {
                    continue;
                }
                if t >= walk_s {
                    break;
                }
            }
        }
    }
    write_file(&out, &figure(&samples, &TerrainConfig::default(), &title(&samples)))
        .map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", summary(&samples, started.elapsed().as_secs_f64(), &out));
    Ok(())
}
