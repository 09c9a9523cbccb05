//! `planner/check_route` over DDS from a Rust client, against the same check in-process: the
//! 20 waypoints round the built-in world's demo loop, MOBIL-II (`params/mobil2.yaml`), from a
//! given start (`use_start`). Budget: the service's median round trip within 2× the median
//! in-process time of what the node does for a request (the check, the answer and the reply
//! message).
//!
//!     cargo build --release --bin planner_node && cargo bench -p mobil_planner_node --bench check_route
//!
//! The bench starts `planner_node` (from `MOBIL_BIN_DIR`, default `target/release`) on a
//! domain of its own, waits for the first answer (discovery), sends 20 calls to warm up, then
//! times 300 calls one after the other. The node's answer must equal the in-process one (the
//! same work). Reported: the in-process medians of the library check alone and of the node's
//! work (check, answer, reply message), both in a loop of their own, and of the node's work
//! timed once before each round of calls (with p90 / p99); the reply's CDR encoding and decoding
//! in-process; the round trip's p50 / p90 / p99; and the ratio of the round trip's median to
//! each of the two medians of the node's work (the budget's is the one timed between the
//! calls). Interleaved with those calls, two more kinds show where the rest goes: a request
//! refused at once (no check, a reply of a few bytes: DDS's floor) and a 1-waypoint route (a
//! check of a few microseconds, then the small reply). The last row is the transport without
//! DDS: UDP round trips on loopback between two threads with the same request and reply sizes.

#[path = "../../planner/benches/common/demo_loop.rs"]
mod demo_loop;

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use mobil_geom::Pose2;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav_msgs::msg::Path;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::RosService;
use mobil_planner::check_route_until;
use mobil_planner_node::{check_reply, load_world, PlannerConfig, RouteAnswer, MAX_REPLY_POSES, ROUTE_LIMITS};
use mobil_ros::config::{load, Decl};
use mobil_ros::geometry::pose_msg;
use mobil_ros::goal::route_from_path;
use mobil_ros::params::initial_params;
use mobil_ros::{qos, NodeDecl, RosNode};
use ros2_client::{Name, ServiceMapping};

const WARM_UP: usize = 20;
const CALLS: usize = 300;

/// Kills the node when the bench ends, however it ends.
struct Node(Child);

impl Drop for Node {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() -> anyhow::Result<()> {
    // A domain of its own, so that no other graph answers or listens: the bench runs itself
    // again with ROS_DOMAIN_ID set.
    if std::env::var_os("ROS_DOMAIN_ID").is_none() {
        let domain = 150 + std::process::id() % 60;
        let status = Command::new(std::env::current_exe()?)
            .args(std::env::args().skip(1))
            .env("ROS_DOMAIN_ID", domain.to_string())
            .status()?;
        std::process::exit(status.code().unwrap_or(1));
    }
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let bin_dir = std::env::var("MOBIL_BIN_DIR").unwrap_or_else(|_| format!("{root}/target/release"));
    let _node = Node(
        Command::new(format!("{bin_dir}/planner_node"))
            .args(["--ros-args", "--params-file", &format!("{root}/params/mobil2.yaml")])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| anyhow::anyhow!("cannot start {bin_dir}/planner_node (build it first): {e}"))?,
    );

    let start = Pose2::identity();
    let route: Vec<_> = demo_loop::demo_loop(20);
    let request = CheckRouteRequest {
        route: Path {
            header: Header {
                stamp: Time::default(),
                frame_id: "odom".into(),
            },
            poses: route
                .iter()
                .map(|p| PoseStamped {
                    header: Header {
                        stamp: Time::default(),
                        frame_id: "odom".into(),
                    },
                    pose: pose_msg(&Pose2::new(p.x, p.y, 0.0)),
                })
                .collect(),
        },
        use_start: true,
        start: pose_msg(&start),
    };

    // In-process: what the node does for this request, with the node's configuration read from
    // the same file.
    let text = std::fs::read_to_string(format!("{root}/params/mobil2.yaml"))?;
    let specs = Decl::<PlannerConfig>::of().specs();
    let initial = initial_params(&specs, &[("mobil2.yaml".into(), text)], &[], "/planner", "planner")?;
    let cfg: PlannerConfig = load(&initial.values)?;
    let chassis = cfg.chassis_params()?;
    let world = load_world(&cfg.world_file)?;
    let config = cfg.route_check();
    let step = cfg.follow.check_length;
    let planned = route_from_path(&request.route, "odom", Some(start.position()), ROUTE_LIMITS)?;
    let local = || {
        let report = check_route_until(&start, &planned.points, &chassis, &world, &config, || false).expect("valid");
        let answer = RouteAnswer::of(
            &report,
            (&planned.points[..], &planned.request_index[..]),
            step,
            MAX_REPLY_POSES,
        );
        check_reply(&answer, Time::default(), "odom")
    };
    let expected = local();
    let time_median = |f: &dyn Fn()| {
        for _ in 0..WARM_UP {
            f();
        }
        let mut t: Vec<f64> = (0..CALLS)
            .map(|_| {
                let t0 = Instant::now();
                f();
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        t.sort_by(f64::total_cmp);
        percentile(&t, 0.5)
    };
    let check_alone = time_median(&|| {
        std::hint::black_box(check_route_until(&start, &planned.points, &chassis, &world, &config, || false).ok());
    });
    let in_process = time_median(&|| {
        std::hint::black_box(local());
    });
    // The reply's CDR encoding (on the node) and decoding (on the client), as the service
    // layer does them: measured apart, they are part of the transfer, not of the node's work.
    let encode = || cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&expected).expect("a reply encodes");
    let encoded = encode();
    let encode_time = time_median(&|| {
        std::hint::black_box(encode());
    });
    let decode_time = time_median(&|| {
        std::hint::black_box(cdr_encoding::from_bytes::<CheckRouteResponse, byteorder::LittleEndian>(&encoded).ok());
    });

    // The transport's floor, without DDS: a UDP round trip on loopback to a thread that answers
    // each datagram with one of the size it asks for, blocking sockets on both sides. Requests as
    // large as the service request's CDR; replies of 64 bytes (a small reply) and as large as the
    // check's CDR.
    let request_size = cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&request)?.len();
    let [udp_small, udp_large] = udp_round_trips(request_size, [64, encoded.len()])?;

    let runtime = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    let trips = runtime.block_on(async {
        let decl = NodeDecl::new("check_route_bench", "planner/check_route round trips");
        let args = decl
            .parse_command_line(["check_route_bench"])?
            .ok_or_else(|| anyhow::anyhow!("no arguments"))?;
        let mut node = RosNode::start(&decl, &args)?;
        let name = Name::parse("/planner/check_route").map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let qos = qos::reliable(10);
        let client = node
            .inner()
            .create_client::<CheckRouteRequest, CheckRouteResponse>(
                ServiceMapping::Enhanced,
                &name,
                &CheckRoute::type_name(),
                qos.clone(),
                qos,
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        // Discovery: ask until the first answer.
        let deadline = Instant::now() + Duration::from_secs(30);
        let first = loop {
            anyhow::ensure!(Instant::now() < deadline, "planner/check_route did not answer in 30 s");
            if let Ok(Ok(reply)) =
                tokio::time::timeout(Duration::from_secs(1), client.async_call_service(request.clone())).await
            {
                break reply;
            }
        };
        anyhow::ensure!(
            first.problems.len() == expected.problems.len()
                && (first.length - expected.length).abs() < 1e-9
                && first.simulated_path.poses.len() == expected.simulated_path.poses.len(),
            "the node's answer differs from the in-process one: {} problems, {} m against {}, {} m",
            first.problems.len(),
            first.length,
            expected.problems.len(),
            expected.length
        );
        // The floor: a request the node refuses at once (a NaN start), a reply of a few bytes.
        let mut refused = request.clone();
        refused.start.position.x = f64::NAN;
        // A check of a single waypoint 0.3 m ahead: a check of a few microseconds, then the
        // small reply.
        let mut short = request.clone();
        short.route.poses.truncate(1);
        short.route.poses[0].pose = pose_msg(&Pose2::new(0.3, 0.0, 0.0));
        let answer = tokio::time::timeout(Duration::from_secs(5), client.async_call_service(short.clone()))
            .await
            .map_err(|_| anyhow::anyhow!("the 1-waypoint call: no answer in 5 s"))?
            .map_err(|e| anyhow::anyhow!("the 1-waypoint call: {e:?}"))?;
        anyhow::ensure!(
            answer.feasible && !answer.simulated_path.poses.is_empty(),
            "the 1-waypoint route was not checked: {answer:?}"
        );
        let mut trips = [
            Vec::with_capacity(CALLS),
            Vec::with_capacity(CALLS),
            Vec::with_capacity(CALLS),
            Vec::with_capacity(CALLS),
        ];
        for k in 0..WARM_UP + CALLS {
            // The in-process work once before each round of calls: the ratio then compares
            // times taken over the same minutes (this machine's speed changes between runs by
            // up to 1.5×), each after DDS work as the node's checks are, not warm from the
            // check before.
            let t0 = Instant::now();
            std::hint::black_box(local());
            if k >= WARM_UP {
                trips[3].push(t0.elapsed().as_secs_f64() * 1e3);
            }
            for (times, req) in trips.iter_mut().zip([&request, &refused, &short]) {
                let t0 = Instant::now();
                let reply = tokio::time::timeout(Duration::from_secs(5), client.async_call_service(req.clone()))
                    .await
                    .map_err(|_| anyhow::anyhow!("call {k}: no answer in 5 s"))?
                    .map_err(|e| anyhow::anyhow!("call {k}: {e:?}"))?;
                if k >= WARM_UP {
                    times.push(t0.elapsed().as_secs_f64() * 1e3);
                }
                std::hint::black_box(reply);
            }
        }
        node.shutdown().await;
        anyhow::Ok(trips)
    })?;
    let [mut trips, mut floor, mut short, mut between] = trips;
    for t in [&mut trips, &mut floor, &mut short, &mut between] {
        t.sort_by(f64::total_cmp);
    }
    let p50 = percentile(&trips, 0.5);
    let in_process_between = percentile(&between, 0.5);
    println!(
        "planner/check_route, 20 waypoints, MOBIL-II, built-in world; reply {} poses, {} problems",
        expected.simulated_path.poses.len(),
        expected.problems.len()
    );
    println!();
    println!("| what | median (ms) | p90 (ms) | p99 (ms) |");
    println!("|---|---:|---:|---:|");
    println!("| in-process: the check alone | {check_alone:.3} | | |");
    println!("| in-process: check, answer, reply message | {in_process:.3} | | |");
    println!(
        "| in-process: the same, once before each round of calls | {in_process_between:.3} | {:.3} | {:.3} |",
        percentile(&between, 0.9),
        percentile(&between, 0.99)
    );
    println!(
        "| in-process: the reply's CDR encoding / decoding ({} bytes) | {encode_time:.3} / {decode_time:.3} | | |",
        encoded.len()
    );
    println!(
        "| Rust client, round trip ({CALLS} calls) | {p50:.3} | {:.3} | {:.3} |",
        percentile(&trips, 0.9),
        percentile(&trips, 0.99)
    );
    println!(
        "| Rust client, a request refused at once (the floor) | {:.3} | {:.3} | {:.3} |",
        percentile(&floor, 0.5),
        percentile(&floor, 0.9),
        percentile(&floor, 0.99)
    );
    println!(
        "| Rust client, a 1-waypoint route 0.3 m ahead | {:.3} | {:.3} | {:.3} |",
        percentile(&short, 0.5),
        percentile(&short, 0.9),
        percentile(&short, 0.99)
    );
    println!(
        "| UDP on loopback between two threads, no DDS: a {request_size}-byte request, a 64-byte / {}-byte reply | {:.3} / {:.3} | | |",
        encoded.len(),
        udp_small,
        udp_large
    );
    println!();
    println!(
        "round trip / in-process: {:.2}× (the work timed between the calls); {:.2}× (timed in a loop of its own)",
        p50 / in_process_between,
        p50 / in_process
    );
    Ok(())
}

/// Median round trip (ms) of `CALLS` UDP requests of `request_size` bytes on loopback, each
/// answered by an echo thread with a datagram of the size the request names, for each reply
/// size.
fn udp_round_trips<const N: usize>(request_size: usize, reply_sizes: [usize; N]) -> anyhow::Result<[f64; N]> {
    use std::net::UdpSocket;
    let server = UdpSocket::bind("127.0.0.1:0")?;
    let client = UdpSocket::bind("127.0.0.1:0")?;
    client.connect(server.local_addr()?)?;
    client.set_read_timeout(Some(Duration::from_secs(5)))?;
    let echo = std::thread::spawn(move || {
        let mut buf = vec![0u8; 65_536];
        let reply = vec![0u8; 65_507];
        // A request of fewer than 8 bytes ends the thread.
        while let Ok((n, from)) = server.recv_from(&mut buf) {
            let Some(size) = buf.get(..8).filter(|_| n >= 8) else {
                break;
            };
            let size = u64::from_le_bytes(size.try_into().unwrap_or_default()) as usize;
            if server.send_to(&reply[..size.min(reply.len())], from).is_err() {
                break;
            }
        }
    });
    let mut request = vec![0u8; request_size.max(8)];
    let mut buf = vec![0u8; 65_536];
    let mut medians = [0.0; N];
    for (median, size) in medians.iter_mut().zip(reply_sizes) {
        request[..8].copy_from_slice(&(size as u64).to_le_bytes());
        let mut t = Vec::with_capacity(CALLS);
        for k in 0..WARM_UP + CALLS {
            let t0 = Instant::now();
            client.send(&request)?;
            let n = client.recv(&mut buf)?;
            anyhow::ensure!(n == size, "a {n}-byte UDP reply where {size} bytes were asked for");
            if k >= WARM_UP {
                t.push(t0.elapsed().as_secs_f64() * 1e3);
            }
        }
        t.sort_by(f64::total_cmp);
        *median = percentile(&t, 0.5);
    }
    client.send(&[0u8])?;
    echo.join()
        .map_err(|_| anyhow::anyhow!("the UDP echo thread panicked"))?;
    Ok(medians)
}
