//! Terminal output of the workflows' events: lines to stdout, notes to stderr, sampling and cloth steps as
//! progress bars on stderr.

use hylc::workflow::Event;
use indicatif::{ProgressBar, ProgressStyle};

/// The progress bar of a sampling run (`hylc sample`, `hylc run`).
pub fn sample_bar(todo: usize) -> ProgressBar {
    bar(
        todo,
        "{elapsed_precise} [{bar:40}] {pos}/{len} samples, {per_sec}, eta {eta}",
    )
}

fn bar(len: usize, template: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}

/// Prints a workflow's events.
#[derive(Default)]
pub struct Printer {
    /// Hide the progress bars.
    quiet: bool,
    samples: Option<ProgressBar>,
    steps: Option<ProgressBar>,
}

impl Printer {
    /// A printer whose progress bars are hidden when `quiet`.
    pub fn new(quiet: bool) -> Self {
        Printer {
            quiet,
            ..Printer::default()
        }
    }

    pub fn show(&mut self, e: Event) {
        match e {
            Event::Log(line) | Event::Print(line) => println!("{line}"),
            Event::Note(line) => eprintln!("{line}"),
            Event::Samples { done, todo } => {
                let quiet = self.quiet;
                let b = self.samples.get_or_insert_with(|| {
                    if quiet {
                        ProgressBar::hidden()
                    } else {
                        sample_bar(todo)
                    }
                });
                b.set_position(done as u64);
                if done >= todo {
                    b.finish_and_clear();
                    self.samples = None;
                }
            }
            Event::Step {
                done,
                total,
                time,
                newton,
                residual,
            } => {
                let quiet = self.quiet;
                let b = self.steps.get_or_insert_with(|| {
                    if quiet {
                        ProgressBar::hidden()
                    } else {
                        bar(
                            total,
                            "{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta} {msg}",
                        )
                    }
                });
                b.set_message(format!(
                    "t = {time:.3} s, {newton} Newton, residual {residual:.1e} N"
                ));
                b.inc(1);
                if done >= total {
                    b.finish_and_clear();
                    self.steps = None;
                }
            }
        }
    }
}
