//! `linalg` room errors into statuses: [`Operand`]s and [`LinalgParam`]s become
//! `SolveLinearSystemRequest` fields, or `IkOptions` fields when the solve runs
//! inside IK.

use tonic::Status;

use super::invalid;
use kinplan_core::linalg::{LinalgError, LinalgParam, Operand};

/// The request a linear solve serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveAt {
    /// `SolveLinearSystem`: operands `a`, `b` and the solver fields.
    LinearSystem,
    /// The RLXA inside an IK iteration: parameters are `options.rlxa_*`.
    IkOptions,
}

/// The request field of a solver parameter.
pub fn param_field(param: LinalgParam, at: SolveAt) -> String {
    match (at, param) {
        (SolveAt::LinearSystem, LinalgParam::SingularValueTolerance) => "singular_value_tolerance".into(),
        (SolveAt::LinearSystem, p) => p.name().into(),
        (SolveAt::IkOptions, LinalgParam::SingularValueTolerance) => {
            "options.singular_value_tolerance".into()
        }
        (SolveAt::IkOptions, p) => format!("options.rlxa_{}", p.name()),
    }
}

/// INVALID_ARGUMENT naming the request field behind a refused linear solve.
pub fn linalg_error(err: LinalgError, at: SolveAt) -> Status {
    let text = err.to_string();
    match err {
        LinalgError::InvalidParam { field, .. } => invalid(param_field(field, at), text),
        LinalgError::ShapeMismatch { .. } => invalid("b", text),
        LinalgError::Empty { .. } => invalid("a", text),
        LinalgError::NonFinite { what: Operand::B } => invalid("b", text),
        LinalgError::NonFinite { what: Operand::A } => invalid("a.data", text),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(err: LinalgError, at: SolveAt) -> String {
        let status = linalg_error(err, at);
        assert_eq!(status.code(), tonic::Code::InvalidArgument);
        status.message().split(':').next().unwrap().to_string()
    }

    fn param(field: LinalgParam) -> LinalgError {
        LinalgError::InvalidParam {
            field,
            value: 0.0,
            reason: "",
        }
    }

    #[test]
    fn operands_and_parameters_name_request_fields() {
        use LinalgParam::*;
        use SolveAt::*;
        let cases = [
            (
                LinalgError::NonFinite { what: Operand::A },
                LinearSystem,
                "a.data",
            ),
            (LinalgError::NonFinite { what: Operand::B }, LinearSystem, "b"),
            (
                LinalgError::ShapeMismatch {
                    rows: 2,
                    cols: 2,
                    rhs_len: 3,
                },
                LinearSystem,
                "b",
            ),
            (LinalgError::Empty { rows: 0, cols: 2 }, LinearSystem, "a"),
            (param(MaxIterations), LinearSystem, "max_iterations"),
            (param(Tolerance), LinearSystem, "tolerance"),
            (param(RelativeTolerance), LinearSystem, "relative_tolerance"),
            (
                param(SingularValueTolerance),
                LinearSystem,
                "singular_value_tolerance",
            ),
            (param(MaxIterations), IkOptions, "options.rlxa_max_iterations"),
            (param(Tolerance), IkOptions, "options.rlxa_tolerance"),
        ];
        for (err, at, field) in cases {
            assert_eq!(field_of(err, at), field);
        }
    }
}
