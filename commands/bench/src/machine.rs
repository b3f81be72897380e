//! The machine a bench ran on, for the report and the plot's label: timings mean
//! nothing without it.

use serde::{Deserialize, Serialize};

/// What the report says about the machine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// The processor's model name (from `/proc/cpuinfo` on Linux), or `unknown`.
    pub cpu: String,
    /// Logical processors available to this process.
    pub threads: usize,
    /// Operating system and architecture, e.g. `linux x86_64`.
    pub os: String,
}

impl Machine {
    pub fn this_one() -> Self {
        Self {
            cpu: cpu_model().unwrap_or_else(|| "unknown".into()),
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        }
    }

    /// One line: `Intel Xeon … (2 threads, linux x86_64)`.
    pub fn label(&self) -> String {
        format!("{} ({} threads, {})", self.cpu, self.threads, self.os)
    }
}

fn cpu_model() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    info.lines()
        .find_map(|l| l.strip_prefix("model name"))
        .and_then(|rest| rest.split_once(':'))
        .map(|(_, name)| name.split_whitespace().collect::<Vec<_>>().join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_label_names_threads_and_system() {
        let m = Machine::this_one();
        assert!(m.threads >= 1);
        assert!(m.label().contains(&format!("{} threads", m.threads)));
        assert!(m.label().contains(std::env::consts::ARCH));
    }
}
