//! What a run leaves behind: one record per pair, and the files written from them
//! (`verge.csv`, `verge.png`, `summary.json`, `matches.csv` when asked), each staged and moved into place whole.

pub mod matches_csv;
pub mod output_dir;
pub mod plot;
pub mod record;
pub mod report;
pub mod summary;
pub mod verge_csv;
