//! Service replies of every size near the largest UDP datagram, between two participants of
//! this host. Such peers talk over loopback, where a datagram may carry up to 64 KB: a reply
//! goes out whole in one datagram up to the datagram budget, in DATA_FRAGs above it. Every reply
//! must arrive. One that crossed the 65 507 bytes IPv4 allows in a datagram would be refused by
//! the kernel, and its repairs as well: the call would never be answered.
//!
//! The sweep takes the reply's `reason` through 63 000..66 000 bytes in steps of 7 (the reply's
//! size moves with it byte for byte), then 100 KB and 300 KB. Server and client are separate
//! participants (one `Context` each) on a domain and service name of this test process only.
//! They are same-host peers (each one's discovery also goes to 127.0.0.1, and what arrives from
//! there marks its sender as on this host), so replies go over loopback in datagrams of up to
//! 64 KB: with the earlier 65 480-byte datagram budget, the reply with a 65 324-byte `reason` was
//! never answered here. A reply is given 30 s: a 64 KB datagram lost under load is repaired
//! 256-byte fragment by fragment.

use std::time::{Duration, Instant};

use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::RosService;
use mobil_ros::qos;
use ros2_client::{Name, ServiceMapping};

use crate::common;

/// The lengths of `reason` asked for, in order.
fn lengths() -> impl Iterator<Item = usize> {
    (63_000..66_000).step_by(7).chain([100_000, 300_000])
}

#[test]
fn replies_of_every_size_near_the_datagram_limit_arrive() {
    let (_server_context, mut server_node) = common::participant("large_replies_server");
    let (_client_context, mut client_node) = common::participant("large_replies_client");
    let name = Name::new("/", &format!("large_replies_{}", std::process::id())).expect("service name");
    let qos = qos::reliable(10);
    let server = server_node
        .create_server::<CheckRouteRequest, CheckRouteResponse>(
            ServiceMapping::Enhanced,
            &name,
            &CheckRoute::type_name(),
            qos.clone(),
            qos.clone(),
        )
        .expect("server");
    let client = client_node
        .create_client::<CheckRouteRequest, CheckRouteResponse>(
            ServiceMapping::Enhanced,
            &name,
            &CheckRoute::type_name(),
            qos.clone(),
            qos,
        )
        .expect("client");

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");
    runtime.block_on(async {
        // The server answers each request with a `reason` as long as the request's start.x; it
        // ends on the first error, which the test then reports.
        let serving = tokio::spawn(async move {
            loop {
                let (id, request) = match server.async_receive_request().await {
                    Ok(received) => received,
                    Err(e) => break format!("receiving a request: {e:?}"),
                };
                let reply = CheckRouteResponse {
                    reason: "x".repeat(request.start.position.x as usize),
                    ..Default::default()
                };
                if let Err(e) = server.send_response(id, reply) {
                    break format!("sending a reply: {e:?}");
                }
            }
        });
        let ask = |length: usize| {
            let mut request = CheckRouteRequest::default();
            request.start.position.x = length as f64;
            client.async_call_service(request)
        };

        // Discovery: ask until the first answer.
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            assert!(Instant::now() < deadline, "no answer within 30 s");
            if let Ok(Ok(reply)) = tokio::time::timeout(Duration::from_secs(1), ask(1)).await {
                assert_eq!(reply.reason, "x");
                break;
            }
        }

        for length in lengths() {
            let Ok(reply) = tokio::time::timeout(Duration::from_secs(30), ask(length)).await else {
                let server = match serving.is_finished() {
                    true => format!("the server stopped: {:?}", serving.await),
                    false => "the server is still serving".to_owned(),
                };
                panic!("the reply with a {length}-byte reason did not arrive in 30 s; {server}");
            };
            let reply = reply.unwrap_or_else(|e| panic!("the call with a {length}-byte reason failed: {e:?}"));
            assert_eq!(reply.reason.len(), length);
            assert!(reply.reason.bytes().all(|b| b == b'x'));
        }
        serving.abort();
    });
}
