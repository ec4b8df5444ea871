//! The platforms robot programs are built for, as data: [`PLATFORMS`], one
//! row per platform with every fact generation needs about it (the runtime
//! layer, the default transport, the runtime files, and for a board its CPU,
//! toolchain, memory, link script, start-up file, clock, timer, serial
//! port and serial link to `semo gateway`). Code generation reads it for each robot's Makefile, the link
//! script and the shared runtime folder; the catalog for a robot type's
//! `<Platform target="...">`; the project file for `[build] target` and
//! `[build.targets]`. A new board is a new row (and its board file in the
//! runtime), not a change to the generator.
//!
//! A [`Target`] is a platform or its simulation: `linux` and `linux-sim`,
//! `cortex-m` and `cortex-m-sim`. The simulation is the same program with
//! sensors, services and the operator taken from a scenario compiled in
//! (`semo build --scenario FILE`) and a trace written (`semo build --sim`
//! picks it for every robot's platform).

/// How a platform runs a robot's tasks: the runtime's platform layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    /// One POSIX thread per task (`semo_runtime.c`).
    Threads,
    /// One loop firing the tasks in the single-appearance schedule's order
    /// (`semo_static.c` and the board's start-up file).
    Static,
}

/// How a robot program reaches the other robots by default (overridable at
/// run time with `--transport`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// UDP on 127.0.0.1, a port per robot (`semo_udp.c`): no broker needed.
    Udp,
    /// An MQTT broker through libmosquitto (`semo_mqtt.c`, `-lmosquitto`).
    Mqtt,
}

impl Transport {
    /// The name `--transport` and the Makefile's `TRANSPORT` take.
    pub fn name(self) -> &'static str {
        match self {
            Transport::Udp => "udp",
            Transport::Mqtt => "mqtt",
        }
    }
}

/// A platform: a row of [`PLATFORMS`].
#[derive(Debug, PartialEq, Eq)]
pub struct Platform {
    /// Its target's name (`linux`); its simulation is `<name>-sim`.
    pub name: &'static str,
    /// One line for completion and messages.
    pub doc: &'static str,
    pub layer: Layer,
    /// The program itself.
    pub real: Variant,
    /// Its simulation (a scenario's sensors, services and operator, a trace).
    pub sim: Variant,
    /// The board of a bare-metal platform; `None` on an operating system.
    pub board: Option<Board>,
}

/// What differs between a platform's program and its simulation.
#[derive(Debug, PartialEq, Eq)]
pub struct Variant {
    /// The default network transport its Makefile builds in; `None`: no
    /// network (a board: the operator through its trace, other robots
    /// through its [`SerialLink`] to `semo gateway`).
    pub transport: Option<Transport>,
    /// The runtime files it compiles, in the runtime folder (for a board,
    /// its start-up file and link script come after these).
    pub runtime: &'static [&'static str],
}

/// A bare-metal board: everything its Makefile and link script say.
#[derive(Debug, PartialEq, Eq)]
pub struct Board {
    /// The microcontroller (`TI Stellaris LM3S6965`).
    pub name: &'static str,
    /// Its core (`Cortex-M3`).
    pub cpu: &'static str,
    /// The compiler's and linker's flags for the core.
    pub arch: &'static str,
    pub toolchain: Toolchain,
    pub flash: Memory,
    pub ram: Memory,
    /// The runtime file with the vector table, reset code, clock and serial
    /// port (`semo_lm3s6965.c`).
    pub startup: &'static str,
    /// The link script in the runtime folder, written from
    /// [`Board::flash`] and [`Board::ram`].
    pub link_script: &'static str,
    /// The main stack's default size (`make SEMO_STACK_BYTES=...`).
    pub stack_bytes: u32,
    /// The core clock the timer counts.
    pub clock_hz: u32,
    /// The timer the start-up file keeps mission time with.
    pub timer: &'static str,
    /// The serial port the trace goes to.
    pub serial: &'static str,
    /// The serial link to `semo gateway` for a robot that messages other
    /// robots: every board has one, so no robot is refused for its
    /// messages.
    pub link: SerialLink,
    /// The emulator `make run` starts, and its machine.
    pub emulator: &'static str,
    pub machine: &'static str,
}

/// A board's serial link to `semo gateway` (`docs/link.md`): what a robot
/// that messages other robots adds to the board's program.
#[derive(Debug, PartialEq, Eq)]
pub struct SerialLink {
    /// The serial port (`UART1`).
    pub port: &'static str,
    /// Its pins, for wiring a real board.
    pub pins: &'static str,
    /// Its default rate (`make SEMO_LINK_BAUD=...`).
    pub baud: u32,
    /// The runtime files the link adds (compiled only into the robots that
    /// message other robots).
    pub runtime: &'static [&'static str],
}

/// The runtime files of the serial link on a board: the frames and
/// sessions, the static schedule's transport over them, and the robot's
/// status sent on it.
pub const LINK_RUNTIME: [&str; 4] = [
    "semo_link.h",
    "semo_link.c",
    "semo_static_link.c",
    "semo_static_status.c",
];

/// The cross toolchain of a board.
#[derive(Debug, PartialEq, Eq)]
pub struct Toolchain {
    pub cc: &'static str,
    pub size: &'static str,
    /// The C library, for people (`newlib-nano`), and the specs file that
    /// links it.
    pub libc: &'static str,
    pub specs: &'static str,
}

/// A memory region of a board.
#[derive(Debug, PartialEq, Eq)]
pub struct Memory {
    pub origin: u32,
    pub kib: u32,
}

/// The runtime files every platform compiles: the API, what the runtime's
/// files share and the portable core.
const CORE: [&str; 3] = ["semo_runtime.h", "semo_internal.h", "semo_core.c"];

/// The runtime files of a Cortex-M board's static schedule: the core, the
/// loop and what every Cortex-M shares (reset, SysTick clock, sleep, exit) (its start-up file and link script
/// come from its [`Board`]).
const CORTEX_M: [&str; 5] = [
    CORE[0],
    CORE[1],
    CORE[2],
    "semo_static.c",
    "semo_cortex_m.c",
];

/// A Cortex-M board's program: the static schedule, no network (other
/// robots only through the board's [`SerialLink`]).
const BOARD_PROGRAM: Variant = Variant {
    transport: None,
    runtime: &CORTEX_M,
};

/// Its simulation's runtime: the program's, and lock-step on the link's
/// serial port (`make LOCKSTEP=1`, `semo simulate --engine c --boards`),
/// for every robot, messaging or not.
const CORTEX_M_SIM: [&str; 6] = [
    CORTEX_M[0],
    CORTEX_M[1],
    CORTEX_M[2],
    CORTEX_M[3],
    CORTEX_M[4],
    "semo_static_lockstep.c",
];

/// A Cortex-M board's simulation: its program's variant, with lock-step.
const BOARD_SIM: Variant = Variant {
    transport: None,
    runtime: &CORTEX_M_SIM,
};

/// The cross toolchain of the Cortex-M boards (Debian's
/// `gcc-arm-none-eabi` and `libnewlib-arm-none-eabi`).
const ARM_NONE_EABI: Toolchain = Toolchain {
    cc: "arm-none-eabi-gcc",
    size: "arm-none-eabi-size",
    libc: "newlib-nano",
    specs: "nano.specs",
};

/// Every platform, in the order targets are listed.
pub const PLATFORMS: &[Platform] = &[
    Platform {
        name: "linux",
        doc: "Linux: one POSIX thread per task",
        layer: Layer::Threads,
        real: Variant {
            transport: Some(Transport::Mqtt),
            runtime: &[
                CORE[0],
                CORE[1],
                CORE[2],
                "semo_runtime.c",
                "semo_udp.c",
                "semo_mqtt.c",
                "semo_link.h",
                "semo_link.c",
                "semo_link_transport.c",
            ],
        },
        sim: Variant {
            transport: Some(Transport::Udp),
            runtime: &[
                CORE[0],
                CORE[1],
                CORE[2],
                "semo_runtime.c",
                "semo_udp.c",
                "semo_mqtt.c",
                "semo_link.h",
                "semo_link.c",
                "semo_link_transport.c",
                "semo_sim.c",
                "semo_lockstep.c",
            ],
        },
        board: None,
    },
    Platform {
        name: "cortex-m",
        doc: "bare metal on a Cortex-M3 (TI Stellaris LM3S6965): a static schedule, no threads, no heap",
        layer: Layer::Static,
        real: BOARD_PROGRAM,
        sim: BOARD_SIM,
        board: Some(Board {
            name: "TI Stellaris LM3S6965",
            cpu: "Cortex-M3",
            arch: "-mcpu=cortex-m3 -mthumb",
            toolchain: ARM_NONE_EABI,
            flash: Memory {
                origin: 0x0000_0000,
                kib: 256,
            },
            ram: Memory {
                origin: 0x2000_0000,
                kib: 64,
            },
            startup: "semo_lm3s6965.c",
            link_script: "lm3s6965.ld",
            stack_bytes: 2048,
            clock_hz: 12_000_000,
            timer: "SysTick",
            serial: "UART0",
            link: SerialLink {
                port: "UART1",
                pins: "U1Rx on PD2, U1Tx on PD3",
                baud: 115_200,
                runtime: &LINK_RUNTIME,
            },
            emulator: "qemu-system-arm",
            machine: "lm3s6965evb",
        }),
    },
    Platform {
        name: "stm32f4",
        doc: "bare metal on a Cortex-M4 (ST STM32F405, the OpenCR's family): a static schedule, no threads, no heap",
        layer: Layer::Static,
        real: BOARD_PROGRAM,
        sim: BOARD_SIM,
        board: Some(Board {
            name: "ST STM32F405",
            cpu: "Cortex-M4",
            // Soft-float, as on the Cortex-M3: the FPU stays off.
            arch: "-mcpu=cortex-m4 -mthumb",
            toolchain: ARM_NONE_EABI,
            flash: Memory {
                origin: 0x0800_0000,
                kib: 1024,
            },
            // SRAM1 and SRAM2, one after the other (the 64 KiB of
            // core-coupled memory at 0x10000000 are left out).
            ram: Memory {
                origin: 0x2000_0000,
                kib: 128,
            },
            startup: "semo_stm32f405.c",
            link_script: "stm32f405.ld",
            stack_bytes: 2048,
            clock_hz: 168_000_000,
            timer: "SysTick",
            serial: "USART1",
            link: SerialLink {
                port: "USART2",
                pins: "TX on PA2, RX on PA3 (alternate function 7)",
                baud: 115_200,
                runtime: &LINK_RUNTIME,
            },
            emulator: "qemu-system-arm",
            machine: "netduinoplus2",
        }),
    },
];

/// A code-generation target: a platform, or its simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Target {
    /// POSIX threads on Linux; the user fills the task files.
    Linux,
    /// The same program with sensors, actuators and the operator simulated
    /// from a scenario file, writing a trace.
    LinuxSim,
    /// Bare metal on a Cortex-M3 (TI Stellaris LM3S6965): a static schedule,
    /// no threads, no heap; the user fills the task files.
    CortexM,
    /// The same with the scenario compiled in as tables (`semo build
    /// --scenario FILE`), tracing on the serial port and exiting through
    /// semihosting, so that a run in the emulator is a test.
    CortexMSim,
    /// Bare metal on a Cortex-M4 (ST STM32F405): as [`Target::CortexM`].
    Stm32F4,
    /// Its simulation, as [`Target::CortexMSim`].
    Stm32F4Sim,
}

impl Target {
    /// Every target, as listed to users.
    pub const ALL: [Target; 6] = [
        Target::Linux,
        Target::LinuxSim,
        Target::CortexM,
        Target::CortexMSim,
        Target::Stm32F4,
        Target::Stm32F4Sim,
    ];

    /// Its name: the platform's, `-sim` after it for the simulation.
    pub fn name(self) -> &'static str {
        match self {
            Target::Linux => "linux",
            Target::LinuxSim => "linux-sim",
            Target::CortexM => "cortex-m",
            Target::CortexMSim => "cortex-m-sim",
            Target::Stm32F4 => "stm32f4",
            Target::Stm32F4Sim => "stm32f4-sim",
        }
    }

    pub fn from_name(name: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Every target's name, in order (for messages and completion).
    pub fn names() -> impl Iterator<Item = &'static str> + Clone {
        Target::ALL.into_iter().map(Target::name)
    }

    /// Its platform's row.
    pub fn platform(self) -> &'static Platform {
        let name = match self {
            Target::Linux | Target::LinuxSim => "linux",
            Target::CortexM | Target::CortexMSim => "cortex-m",
            Target::Stm32F4 | Target::Stm32F4Sim => "stm32f4",
        };
        PLATFORMS
            .iter()
            .find(|p| p.name == name)
            .expect("every target has its platform's row (tested)")
    }

    /// Sensors, services and the operator come from a scenario: at run time
    /// (`--scenario FILE`, POSIX) or compiled in (static, `scenario.c`).
    pub fn simulated(self) -> bool {
        matches!(
            self,
            Target::LinuxSim | Target::CortexMSim | Target::Stm32F4Sim
        )
    }

    /// The simulation of this target's platform (`semo build --sim`).
    pub fn simulation(self) -> Target {
        match self {
            Target::Linux | Target::LinuxSim => Target::LinuxSim,
            Target::CortexM | Target::CortexMSim => Target::CortexMSim,
            Target::Stm32F4 | Target::Stm32F4Sim => Target::Stm32F4Sim,
        }
    }

    fn variant(self) -> &'static Variant {
        let platform = self.platform();
        if self.simulated() {
            &platform.sim
        } else {
            &platform.real
        }
    }

    pub fn layer(self) -> Layer {
        self.platform().layer
    }

    pub fn transport(self) -> Option<Transport> {
        self.variant().transport
    }

    /// The runtime files its programs compile (a board's start-up file and
    /// link script last).
    pub fn runtime(self) -> impl Iterator<Item = &'static str> {
        let board = self.platform().board.as_ref();
        self.variant()
            .runtime
            .iter()
            .copied()
            .chain(
                board
                    .into_iter()
                    .flat_map(|b| b.link.runtime.iter().copied()),
            )
            .chain(board.map(|b| b.startup))
            .chain(board.map(|b| b.link_script))
    }

    /// The scenario is compiled into the program (`semo build --scenario`):
    /// every simulation, on either runtime (no program reads a scenario
    /// file).
    pub fn needs_scenario(self) -> bool {
        self.simulated()
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The platform named `name` (a robot type's `<Platform target="...">`
/// names one: the simulation is a build's choice, not the robot's).
pub fn platform_target(name: &str) -> Option<Target> {
    Target::from_name(name).filter(|t| !t.simulated())
}

/// The platforms' names (a robot type's `target=` takes one).
pub fn platform_names() -> impl Iterator<Item = &'static str> + Clone {
    PLATFORMS.iter().map(|p| p.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_target_is_a_platform_or_its_simulation_and_every_platform_has_both() {
        for target in Target::ALL {
            let platform = target.platform();
            let expected = if target.simulated() {
                format!("{}-sim", platform.name)
            } else {
                platform.name.to_string()
            };
            assert_eq!(target.name(), expected);
            assert_eq!(Target::from_name(target.name()), Some(target));
            assert!(target.simulation().simulated());
            assert_eq!(target.simulation().platform(), platform);
        }
        for platform in PLATFORMS {
            let real = platform_target(platform.name).expect("a target per platform");
            assert_eq!(real.platform(), platform);
            assert!(Target::from_name(&format!("{}-sim", platform.name)).is_some());
            // A board runs a static schedule; an operating system threads.
            assert_eq!(
                platform.board.is_some(),
                platform.layer == Layer::Static,
                "{}",
                platform.name
            );
        }
        assert_eq!(platform_target("linux-sim"), None);
    }
}
