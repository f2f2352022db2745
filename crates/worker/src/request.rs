//! What the page sends the worker: a message of the job protocol, or several files to open as
//! one document (an instance with its result, a nest with its task and tour).
//!
//! The page compiles this same file (`src/worker_client.rs` includes it by path), so both ends
//! agree on the encoding. It belongs in `cutroute-protocol` as a `ToWorker` variant; it lives
//! here until the protocol grows one.

use cutroute_protocol::ToWorker;
use serde::{Deserialize, Serialize};

/// A message to the solver worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum WorkerRequest {
    /// A message of the job protocol.
    Protocol(ToWorker),
    /// Read these files together (parsed in the worker); answered by `FromWorker::Opened` or
    /// `FromWorker::OpenFailed` with the same `request_id`.
    OpenTogether {
        /// Chosen by the sender; echoed in the answer.
        request_id: u64,
        /// Each file's name and bytes.
        files: Vec<(String, Vec<u8>)>,
    },
}
