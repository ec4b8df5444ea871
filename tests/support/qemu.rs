//! Board robots in QEMU for the end-to-end tests: a board's machine, and
//! QEMU running a robot's ELF file with its trace (the first serial port)
//! read line by line and its link (the second) served on a TCP port for
//! `semo gateway` (`docs/link.md`, "On a board").

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;

/// A board family a robot is built for: its simulation target and QEMU's
/// machine.
#[derive(Clone, Copy, Debug)]
pub struct Board {
    pub target: &'static str,
    pub machine: &'static str,
}

/// The TI Stellaris LM3S6965 (UART0 the trace, UART1 the link).
pub const LM3S6965: Board = Board {
    target: "cortex-m-sim",
    machine: "lm3s6965evb",
};

/// The ST STM32F405 (USART1 the trace, USART2 the link).
pub const STM32F405: Board = Board {
    target: "stm32f4-sim",
    machine: "netduinoplus2",
};

/// One line a board wrote on its trace port: the robot's name, the line,
/// and when this process read it (Unix ms: the line was written at or
/// before).
#[derive(Clone, Debug)]
pub struct Line {
    pub robot: String,
    pub read_at_unix_ms: u64,
    pub text: String,
}

pub fn unix_ms() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("the clock is after 1970")
        .as_millis() as u64
}

/// QEMU running `elf` on `board`, its link port served on `link_port` of
/// 127.0.0.1 (the gateway connects to it); each trace line goes to `lines`
/// as it is read, named `robot`, until QEMU ends or is killed. Several
/// boards may share one channel: their lines come in the order they were
/// read.
pub fn spawn(
    elf: &Path,
    board: Board,
    link_port: u16,
    robot: &str,
    lines: mpsc::Sender<Line>,
) -> Child {
    let robot = robot.to_string();
    spawn_with(elf, board, link_port, move |text| {
        let line = Line {
            robot: robot.clone(),
            read_at_unix_ms: unix_ms(),
            text,
        };
        lines.send(line).is_ok()
    })
}

/// QEMU as [`spawn`] starts it, each trace line handed to `line` as it is
/// read, until QEMU ends or `line` says no more.
pub fn spawn_with(
    elf: &Path,
    board: Board,
    link_port: u16,
    mut line: impl FnMut(String) -> bool + Send + 'static,
) -> Child {
    let mut child = Command::new("qemu-system-arm")
        .args(["-M", board.machine, "-display", "none", "-monitor", "none"])
        .args(["-semihosting", "-serial", "stdio", "-serial"])
        .arg(format!(
            "tcp:127.0.0.1:{link_port},server=on,wait=off,nodelay=on"
        ))
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("qemu-system-arm starts");
    let stdout = child.stdout.take().expect("stdout is piped");
    std::thread::spawn(move || {
        for text in BufReader::new(stdout).lines() {
            let Ok(text) = text else { return };
            if !line(text) {
                return;
            }
        }
    });
    child
}
