//! Messages per second through a private mosquitto on loopback with 50
//! robots publishing at 10 Hz (issue 17): `mqtt_throughput.c` forks 50
//! processes, each opening the runtime's own MQTT transport (`semo_mqtt.c`)
//! as one robot of a team of 50; each publishes to its team 10 times a
//! second for 10 s (a `publish`: QoS 0, retained, fanned out by the broker
//! to the 49 others) and counts what reaches it. Prints the messages
//! published and delivered per second, and the share delivered. Needs
//! `mosquitto`, `libmosquitto-dev` and a C compiler; says so and does
//! nothing without them.
//!
//! `cargo bench -p semo-cli --bench mqtt_throughput`

#[path = "support/c_broker_bench.rs"]
mod c_broker_bench;

const ROBOTS: usize = 50;
const RATE_HZ: usize = 10;
const SECONDS: usize = 10;

fn main() {
    let args = [ROBOTS, RATE_HZ, SECONDS].map(|n| n.to_string());
    match c_broker_bench::run("mqtt_throughput", &args) {
        Some(Ok(numbers)) if numbers.len() == 4 => {
            let (published, delivered, expected, wall) =
                (numbers[0], numbers[1], numbers[2], numbers[3]);
            println!(
                "mqtt throughput, {ROBOTS} robot processes publishing at {RATE_HZ} Hz for {SECONDS} s on loopback: {:.0} messages/s published, {:.0} messages/s delivered ({:.2}% of the {expected:.0} fan-out deliveries)",
                published / wall,
                delivered / wall,
                100.0 * delivered / expected.max(1.0)
            )
        }
        Some(Ok(numbers)) => eprintln!("mqtt_throughput failed: it printed {numbers:?}"),
        Some(Err(said)) => eprintln!("mqtt_throughput failed: {said}"),
        None => {}
    }
}
