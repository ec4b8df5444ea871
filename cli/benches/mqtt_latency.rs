//! `send` → `receive` latency through a private mosquitto on loopback, as
//! generated robots see it (issue 17's goal: median ≤ 1 ms, p99 ≤ 5 ms):
//! `mqtt_latency.c` opens the runtime's own MQTT transport (`semo_mqtt.c`,
//! QoS 1, persistent session, TCP_NODELAY) in two processes and times 2000
//! sends one millisecond apart. Needs `mosquitto`, `libmosquitto-dev` and a
//! C compiler; says so and does nothing without them.
//!
//! `cargo bench -p semo-cli --bench mqtt_latency`

#[path = "support/c_broker_bench.rs"]
mod c_broker_bench;

const SENDS: usize = 2000;

fn main() {
    match c_broker_bench::run("mqtt_latency", &[SENDS.to_string()]) {
        Some(Ok(numbers)) if numbers.len() == 3 => {
            let (median, p99, max) = (numbers[0], numbers[1], numbers[2]);
            println!(
                "mqtt send→receive latency over {SENDS} sends on loopback: median {median:.1} µs, p99 {p99:.1} µs, max {max:.1} µs (goal: median ≤ 1000 µs, p99 ≤ 5000 µs)"
            )
        }
        Some(Ok(numbers)) => eprintln!("mqtt_latency failed: it printed {numbers:?}"),
        Some(Err(said)) => eprintln!("mqtt_latency failed: {said}"),
        None => {}
    }
}
