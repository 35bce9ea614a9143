//! The progress bar of an interactive run (stderr; `RunOptions::progress`).

use super::time_grid::TimeGrid;

/// A progress bar over the base steps, updated every 4096 steps.
pub struct Progress(indicatif::ProgressBar);

impl Progress {
    /// A bar when `enabled`, else nothing.
    pub fn new(enabled: bool, n_steps: u64) -> Option<Progress> {
        if !enabled {
            return None;
        }
        let pb = indicatif::ProgressBar::new(n_steps);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {percent:>3}% t={msg} s  elapsed {elapsed_precise} eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Some(Progress(pb))
    }

    /// After base step k.
    #[inline]
    pub fn update(&self, k: u64, grid: &TimeGrid) {
        if k & 0xfff == 0 {
            self.0.set_position(k);
            self.0.set_message(format!("{:.2}", grid.at(k)));
        }
    }

    /// The run ended: the bar goes.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }

    /// The run was interrupted: the bar stays where it stopped.
    pub fn abandon(&self) {
        self.0.abandon();
    }
}
