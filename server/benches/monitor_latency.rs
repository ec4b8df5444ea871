//! The live robot monitor's latency: from a robot's status publish on a
//! private `mosquitto` (loopback) to the `semo/monitor` notification that
//! shows it, through the in-process server (p50/p99 over 500 status
//! changes, one every 5 ms). Run with
//! `cargo bench -p semo-server --bench monitor_latency` (needs `mosquitto`).

#[path = "../tests/support/broker.rs"]
mod broker;

#[path = "../../compiler/benches/common/allocator.rs"]
mod allocator;

use rumqttc::{AsyncClient, MqttOptions, QoS};
use semo_server::harness::TestClient;
use serde_json::json;
use std::time::{Duration, Instant};

const CHANGES: usize = 500;

fn main() {
    let Some(binary) = broker::mosquitto() else {
        return;
    };
    let broker = broker::Broker::start(&binary);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a runtime");
    runtime.block_on(run(broker.port, broker.url()));
}

async fn run(port: u16, url: String) {
    let dir = tempfile::tempdir().unwrap();
    let mission = dir.path().join("follow.mission");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/follow/follow.mission"
    ))
    .unwrap();
    std::fs::write(&mission, &text).unwrap();
    let uri = format!("file://{}", mission.display());
    let mut client = TestClient::start();
    client
        .initialize_with(json!({}), Some(&format!("file://{}", dir.path().display())))
        .await;
    client.open(&uri, &text).await;
    client.diagnostics(&uri, Some(1)).await;
    client
        .request("semo/monitor/start", json!({ "uri": uri, "broker": url }))
        .await
        .expect("the monitor starts");
    client
        .notification("semo/monitor", |p| p["connection"] == "connected")
        .await;

    let (robot, mut eventloop) =
        AsyncClient::new(MqttOptions::new("bench-create1", "127.0.0.1", port), 64);
    tokio::spawn(async move { while eventloop.poll().await.is_ok() {} });
    let mut latencies = Vec::with_capacity(CHANGES);
    for i in 0..CHANGES {
        let mode = format!("MODE_{i}");
        let payload = json!({
            "t": i, "robot": "create1", "event": "status", "state": "running",
            "mode": mode, "leader": "", "services": "Action=RemoteControl",
        });
        let sent = Instant::now();
        robot
            .publish(
                "semo/follow/default/status/create1",
                QoS::AtLeastOnce,
                true,
                payload.to_string(),
            )
            .await
            .unwrap();
        client
            .notification("semo/monitor", |p| p["robots"][0]["mode"] == mode.as_str())
            .await;
        latencies.push(sent.elapsed());
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    latencies.sort();
    let at = |q: f64| latencies[((latencies.len() - 1) as f64 * q) as usize];
    println!(
        "status publish → semo/monitor notification over {CHANGES} changes: p50 {:.2} ms, p99 {:.2} ms, max {:.2} ms",
        at(0.5).as_secs_f64() * 1e3,
        at(0.99).as_secs_f64() * 1e3,
        at(1.0).as_secs_f64() * 1e3,
    );
    client.shutdown().await;
}
