//! Service names and the iceoryx2 configuration of one coupled run (DESIGN §3).
//!
//! Every resource of a run lives under its own file prefix `fsi_<run_id>_` and every service is
//! named `fsi/<run_id>/<name>`, so concurrent runs and tests never see each other, and "no file of
//! this run remains" is one glob (see `shm::cleanup_run`). The configuration is built in code: no
//! config file is read, iceoryx2's own signal handling is disabled (see `liveness`) and so is its
//! automatic clean-up of dead nodes (see [`config`]).

use crate::messages::Role;
use iceoryx2::config::Config;
use iceoryx2::prelude::{
    ipc, FileName, Node, NodeBuilder, NodeName, SemanticString, ServiceName, SignalHandlingMode,
};

use crate::endpoint::ProtocolError;

/// Longest accepted run id (file names carry it twice, and iceoryx2 limits their length).
pub const MAX_RUN_ID_LEN: usize = 40;

/// The participant's service of its `Hello`: `hello/<role>`, history 1.
pub fn hello(role: Role) -> String {
    format!("hello/{}", role.name())
}

/// The launcher -> participant request-response service: `control/<role>`.
pub fn control(role: Role) -> String {
    format!("control/{}", role.name())
}

/// The wake-up event of a reader: `wake/<fluid|structure|launcher>`. Every writer notifies the
/// reader's event after it sent a sample, a command or a reply.
pub fn wake(reader: &str) -> String {
    format!("wake/{reader}")
}

/// Structure -> fluid wet-surface elements, history 1.
pub const TOPOLOGY: &str = "surface/topology";
/// Structure -> fluid wet-node positions and velocities.
pub const KINEMATICS: &str = "surface/kinematics";
/// Fluid -> structure wet-node forces.
pub const LOADS: &str = "surface/loads";
/// The wake event name of the launcher.
pub const LAUNCHER: &str = "launcher";

/// Checks a run id: 1 to `MAX_RUN_ID_LEN` characters of `[A-Za-z0-9-]` (no `_`, which separates
/// the prefix from iceoryx2's own file names).
pub fn validate_run_id(run_id: &str) -> Result<(), ProtocolError> {
    let ok = !run_id.is_empty()
        && run_id.len() <= MAX_RUN_ID_LEN
        && run_id.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-');
    if ok {
        Ok(())
    } else {
        Err(ProtocolError::Setup(format!(
            "invalid run id `{run_id}`: expected 1 to {MAX_RUN_ID_LEN} characters of A-Z, a-z, 0-9 or '-'"
        )))
    }
}

/// The file prefix of every resource of a run.
pub fn prefix(run_id: &str) -> String {
    format!("fsi_{run_id}_")
}

/// The full service name `fsi/<run_id>/<name>`.
pub fn service_name(run_id: &str, name: &str) -> Result<ServiceName, ProtocolError> {
    let full = format!("fsi/{run_id}/{name}");
    ServiceName::new(&full)
        .map_err(|e| ProtocolError::Setup(format!("invalid service name `{full}`: {e:?}")))
}

/// The iceoryx2 configuration of a run: defaults, with the run's file prefix and without
/// iceoryx2's clean-up of dead nodes when a node is created or dropped or a service opened.
///
/// That clean-up reads a dead node's configuration from its details file, and when the file is
/// gone (the node died while being created or removed) falls back to `Config::global_config()`,
/// which looks for a config file and warns on stderr. A run's files are removed by prefix
/// instead: by the launcher when the run ends, and by the next launcher when a run died
/// (`shm::cleanup_stale_runs`).
pub fn config(run_id: &str) -> Result<Config, ProtocolError> {
    validate_run_id(run_id)?;
    let mut config = Config::default();
    let p = prefix(run_id);
    config.global.prefix = FileName::new(p.as_bytes())
        .map_err(|e| ProtocolError::Setup(format!("invalid file prefix `{p}`: {e:?}")))?;
    config.global.node.cleanup_dead_nodes_on_creation = false;
    config.global.node.cleanup_dead_nodes_on_destruction = false;
    config.global.service.cleanup_dead_nodes_on_open = false;
    Ok(config)
}

/// Creates the node of one process in a run, named after its role (`fluid`, `structure`,
/// `launcher`), with iceoryx2's signal handling disabled.
pub fn node(run_id: &str, name: &str) -> Result<Node<ipc::Service>, ProtocolError> {
    let config = config(run_id)?;
    let node_name = NodeName::new(name)
        .map_err(|e| ProtocolError::Setup(format!("invalid node name `{name}`: {e:?}")))?;
    NodeBuilder::new()
        .name(&node_name)
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| {
            ProtocolError::Ipc(format!("cannot create the node `{name}` of run {run_id}: {e:?}"))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_ids_are_checked() {
        assert!(validate_run_id("abc-123").is_ok());
        for bad in ["", "a_b", "a/b", &"x".repeat(MAX_RUN_ID_LEN + 1)] {
            let e = validate_run_id(bad).unwrap_err().to_string();
            assert!(e.contains("invalid run id"), "{e}");
        }
        assert_eq!(service_name("r1", KINEMATICS).unwrap().as_str(), "fsi/r1/surface/kinematics");
    }

    #[test]
    fn the_config_never_cleans_dead_nodes_itself() {
        let c = config("r1").unwrap();
        assert_eq!(c.global.prefix.as_bytes(), b"fsi_r1_");
        assert!(!c.global.node.cleanup_dead_nodes_on_creation);
        assert!(!c.global.node.cleanup_dead_nodes_on_destruction);
        assert!(!c.global.service.cleanup_dead_nodes_on_open);
    }
}
