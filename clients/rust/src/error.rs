//! The one error type of the client: every failed call is an [`Error`] whose
//! [`Error::code`] is the gRPC status code the server (or the transport) gave.

use tonic::Code;

/// What a call returns when it fails.
///
/// - [`Error::Status`]: the server answered with a non-OK status. Bad input is
///   `INVALID_ARGUMENT` with the offending field named in the message (for
///   example `target.position.x: not finite`); an unknown built-in robot is
///   `NOT_FOUND`; a missed deadline is `DEADLINE_EXCEEDED` (the client maps
///   tonic's local "Timeout expired" to that code, so it does not matter which
///   side noticed first).
/// - [`Error::Connect`]: the address could not be parsed or dialled.
/// - [`Error::Reply`]: the server's answer lacked a field the contract requires.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{code:?}: {message}")]
    Status { code: Code, message: String },
    #[error("cannot connect to `{address}`: {reason} (is `kinplan serve` running there?)")]
    Connect { address: String, reason: String },
    #[error("malformed reply: {0}")]
    Reply(&'static str),
}

impl Error {
    /// The gRPC status code: the server's for [`Error::Status`], `UNAVAILABLE`
    /// for [`Error::Connect`], `INTERNAL` for [`Error::Reply`].
    pub fn code(&self) -> Code {
        match self {
            Error::Status { code, .. } => *code,
            Error::Connect { .. } => Code::Unavailable,
            Error::Reply(_) => Code::Internal,
        }
    }

    /// The server's message (empty for connection and reply errors).
    pub fn message(&self) -> &str {
        match self {
            Error::Status { message, .. } => message,
            _ => "",
        }
    }
}

impl From<tonic::Status> for Error {
    fn from(status: tonic::Status) -> Self {
        // tonic's client-side deadline answers CANCELLED "Timeout expired";
        // the server's answers DEADLINE_EXCEEDED: one code for both.
        let code = match status.code() {
            Code::Cancelled if status.message().contains("Timeout expired") => Code::DeadlineExceeded,
            other => other,
        };
        Error::Status {
            code,
            message: status.message().to_owned(),
        }
    }
}

/// The result of every client call.
pub type Result<T> = std::result::Result<T, Error>;
