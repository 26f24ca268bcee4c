//! The columns `campaign.csv` always has, in its order around the conditions and the
//! parameters: what the table writes ([`super::table`]) and what a condition must not be named
//! ([`super::condition_names`]).

/// The columns of `campaign.csv` before the conditions.
pub const LEADING_COLUMNS: [&str; 4] = ["unit", "record", "command", "status"];
/// The column of the model's name, after the conditions.
pub const MODEL_COLUMN: &str = "model";
/// The columns after the parameters.
pub const TRAILING_COLUMNS: [&str; 12] = [
    "rms",
    "rms_unit",
    "aic",
    "bic",
    "converged",
    "best",
    "warnings",
    "validation_rms",
    "effects",
    "gap_before",
    "wall_seconds",
    "error",
];
/// What a parameter's standard-error column adds to its name.
pub const STD_ERROR_SUFFIX: &str = "_std_error";

/// Whether `name` is a column `campaign.csv` always has (`unit`, `status`, `model`, `rms` …),
/// which a condition of that name would duplicate.
pub fn is_fixed_column(name: &str) -> bool {
    LEADING_COLUMNS.contains(&name) || name == MODEL_COLUMN || TRAILING_COLUMNS.contains(&name)
}
