//! Terminal output of the workflows' events.

use hylc::workflow::Event;
use indicatif::{ProgressBar, ProgressStyle};

/// Prints a workflow's events: lines to stdout, notes to stderr, cloth steps as a progress bar.
#[derive(Default)]
pub struct Printer {
    /// Hide the progress bar.
    quiet: bool,
    bar: Option<ProgressBar>,
}

impl Printer {
    /// A printer whose progress bar is hidden when `quiet`.
    pub fn new(quiet: bool) -> Self {
        Printer { quiet, bar: None }
    }

    pub fn show(&mut self, e: Event) {
        match e {
            Event::Log(line) | Event::Print(line) => println!("{line}"),
            Event::Note(line) => eprintln!("{line}"),
            Event::Step {
                done,
                total,
                time,
                newton,
                residual,
            } => {
                let quiet = self.quiet;
                let bar = self.bar.get_or_insert_with(|| {
                    let bar = if quiet {
                        ProgressBar::hidden()
                    } else {
                        ProgressBar::new(total as u64)
                    };
                    if let Ok(style) = ProgressStyle::with_template(
                        "{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta} {msg}",
                    ) {
                        bar.set_style(style);
                    }
                    bar
                });
                bar.set_message(format!(
                    "t = {time:.3} s, {newton} Newton, residual {residual:.1e} N"
                ));
                bar.inc(1);
                if done >= total {
                    bar.finish_and_clear();
                    self.bar = None;
                }
            }
        }
    }
}
