//! `shipsim campaign ...`: run, show, merge and plot campaigns (the binary's part; the work is
//! in [`shipsim::campaign`]).

use clap::Subcommand;
use shipsim::campaign::{self, Campaign, CampaignOptions};
use shipsim::error::Error;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

#[derive(Subcommand)]
pub enum CampaignCommand {
    /// Run a campaign file: every run not done yet, on every core; results in the output folder.
    Run {
        /// The campaign file (TOML).
        file: PathBuf,
        /// Output folder (default: results/<campaign name>). Running again resumes it.
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Worker threads (default: every core).
        #[arg(long, short)]
        jobs: Option<usize>,
        /// Run only shard I of N (0-based, e.g. --shard 0/4), for array jobs across machines.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
        /// Run again the runs that failed before.
        #[arg(long)]
        retry_failed: bool,
        /// No progress bar and no summary.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Show what a campaign file expands to, without running it.
    Show {
        file: PathBuf,
        /// Also list every run with the values it sets.
        #[arg(long)]
        runs: bool,
    },
    /// Combine the output folders of a campaign's shards; report the runs that are missing.
    Merge {
        /// The shard output folders.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// The merged output folder.
        #[arg(long, short)]
        output: PathBuf,
    },
    /// Plot a KPI of a run or derived table (CSV or Parquet, or an output folder: its derived
    /// table if it has one, else its run table).
    Plot {
        table: PathBuf,
        /// line (KPI against a factor, mean and 5-95 % band over seeds), heatmap (over two
        /// factors), polar (KPI against a direction factor in degrees) or histogram (the
        /// distribution of the KPI --x).
        #[arg(long, default_value = "line")]
        kind: String,
        /// The factor on the x axis (polar: the angle, in degrees; histogram: the KPI).
        #[arg(long)]
        x: String,
        /// The KPI (line, polar), or the second factor (heatmap); histogram: not used.
        #[arg(long)]
        y: Option<String>,
        /// heatmap: the KPI coloured over (x, y).
        #[arg(long)]
        z: Option<String>,
        /// One curve per value of this column (line, polar).
        #[arg(long)]
        group: Option<String>,
        #[arg(long)]
        title: Option<String>,
        /// Axis label of --x (default: the column name), e.g. "wave direction [deg]".
        #[arg(long)]
        x_label: Option<String>,
        /// Axis label of --y (polar: the radius), e.g. "roll reduction [%]".
        #[arg(long)]
        y_label: Option<String>,
        /// Legend name of --group, e.g. "H_s [m]".
        #[arg(long)]
        group_label: Option<String>,
        /// PNG output file.
        #[arg(long, short)]
        output: PathBuf,
    },
}

pub fn dispatch(
    cmd: CampaignCommand,
    interrupt: impl Fn() -> std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> shipsim::Result<()> {
    match cmd {
        CampaignCommand::Run {
            file,
            output,
            jobs,
            shard,
            retry_failed,
            quiet,
        } => {
            let c = Campaign::load(&file)?;
            let output = output.unwrap_or_else(|| Path::new("results").join(&c.spec.name));
            let opts = CampaignOptions {
                jobs,
                shard: shard.as_deref().map(parse_shard).transpose()?,
                output,
                progress: !quiet && std::io::stderr().is_terminal(),
                retry_failed,
                interrupt: Some(interrupt()),
                ..Default::default()
            };
            if !quiet {
                eprintln!("{}", describe(&c));
            }
            let outcome = campaign::execute::run(&c, &opts)?;
            if !quiet {
                eprintln!("{outcome}");
            }
            if outcome.interrupted {
                return Err(Error::Interrupted { time: f64::NAN });
            }
            failures(&outcome)
        }
        CampaignCommand::Show { file, runs } => {
            let c = Campaign::load(&file)?;
            show(&c, runs)
        }
        CampaignCommand::Merge { inputs, output } => {
            let report = campaign::merge::merge(&inputs, &output)?;
            println!("{report}");
            if report.missing.is_empty() {
                Ok(())
            } else {
                Err(Error::Other(format!(
                    "{} run(s) missing",
                    report.missing.len()
                )))
            }
        }
        CampaignCommand::Plot {
            table,
            kind,
            x,
            y,
            z,
            group,
            title,
            x_label,
            y_label,
            group_label,
            output,
        } => {
            let req = PlotRequest {
                kind: &kind,
                x: &x,
                y: y.as_deref(),
                z: z.as_deref(),
                group: group.as_deref(),
            };
            let mut opts = campaign::plot::PlotOptions::new(&output);
            opts.title = title;
            opts.x_label = x_label;
            opts.y_label = y_label;
            opts.group_label = group_label;
            plot(&table, &req, &opts)
        }
    }
}

/// A campaign whose runs (of this shard) failed, now or before, ends with status 2 after its
/// tables are written: a script sees it without reading them (issue 38, item 7).
fn failures(outcome: &campaign::execute::CampaignOutcome) -> shipsim::Result<()> {
    let failed = outcome.failed + outcome.failed_before;
    if failed == 0 {
        return Ok(());
    }
    Err(Error::RunsFailed(format!(
        "{failed} of {} runs failed (status and message in runs.csv; --retry-failed runs them again)",
        outcome.selected
    )))
}

/// `campaign show`: the description and, with `runs`, every run with the values it sets, one
/// line each, made as it is written. A reader that stops early (`| head`) ends it quietly.
fn show(c: &Campaign, runs: bool) -> shipsim::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut write = || -> std::io::Result<()> {
        writeln!(out, "{}", describe(c))?;
        for r in c.runs.iter().filter(|_| runs) {
            let sets: Vec<String> = r.sets.iter().map(|(k, v)| format!("{k}={v}")).collect();
            writeln!(out, "{:>6}  {}", r.index, sets.join(" "))?;
        }
        out.flush()
    };
    match write() {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.map_err(|e| Error::io("cannot write to stdout", e)),
    }
}

/// `I/N` with I < N.
fn parse_shard(s: &str) -> shipsim::Result<(usize, usize)> {
    let bad = || {
        Error::Other(format!(
            "--shard {s}: expected I/N with 0 <= I < N, e.g. 0/4"
        ))
    };
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// The campaign in a few lines: system, factors, replications, arms, KPIs, runs.
fn describe(c: &Campaign) -> String {
    let s = &c.spec;
    let mut out = format!(
        "campaign '{}': {} runs of {}",
        s.name,
        c.runs.len(),
        s.system.display()
    );
    for f in &s.factors {
        let levels = match &f.levels {
            campaign::spec::Levels::Grid(v) => format!("{} values {:?}", v.len(), v),
            l => format!("{l:?} ({} samples)", s.sampling.samples),
        };
        out += &format!(
            "\n  factor {} -> {} (x {}): {levels}",
            f.name, f.variable, f.scale
        );
    }
    if !s.replications.seeds.is_empty() {
        out += &format!(
            "\n  {} replication(s), seeds {}",
            s.replications.count,
            s.replications.seeds.join(", ")
        );
    }
    for a in &s.arms {
        let sets: Vec<String> = a.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
        out += &format!("\n  arm {}: {}", a.name, sets.join(", "));
    }
    let kpis: Vec<String> = s.kpis.iter().flat_map(|k| k.columns()).collect();
    out += &format!("\n  KPIs: {}", kpis.join(", "));
    if let Some(t) = s.fork_at {
        out += &format!("\n  warm-up shared up to t = {t} s");
    }
    out
}

/// The figure a `campaign plot` asks for.
pub struct PlotRequest<'a> {
    pub kind: &'a str,
    pub x: &'a str,
    pub y: Option<&'a str>,
    pub z: Option<&'a str>,
    pub group: Option<&'a str>,
}

/// `shipsim campaign plot`: a table file, or an output folder (its derived table if it has
/// one, else its run table).
fn plot<'r>(
    table: &Path,
    req: &PlotRequest<'r>,
    opts: &campaign::plot::PlotOptions,
) -> shipsim::Result<()> {
    use campaign::plot;
    let file = if table.is_dir() {
        let derived = table.join("derived.parquet");
        if derived.exists() {
            derived
        } else {
            table.join("runs.parquet")
        }
    } else {
        table.to_path_buf()
    };
    let t = campaign::table::Table::read(&file)?;
    let need = |v: Option<&'r str>, what: &str| -> shipsim::Result<&'r str> {
        v.ok_or_else(|| Error::Other(format!("campaign plot --kind {}: give {what}", req.kind)))
    };
    let summary = match req.kind {
        "line" => plot::line_band(&t, req.x, need(req.y, "--y (the KPI)")?, req.group, opts)?,
        "polar" => plot::polar(&t, req.x, need(req.y, "--y (the KPI)")?, req.group, opts)?,
        "heatmap" => plot::heatmap(
            &t,
            req.x,
            need(req.y, "--y (the second factor)")?,
            need(req.z, "--z (the KPI)")?,
            opts,
        )?,
        "histogram" => plot::histogram(&t, req.x, req.group, opts)?,
        k => {
            return Err(Error::Other(format!(
                "campaign plot --kind {k}: use line, polar, heatmap or histogram"
            )))
        }
    };
    println!(
        "wrote {} ({} rows of {}{})",
        opts.path.display(),
        summary.rows_used,
        file.display(),
        if summary.rows_skipped > 0 {
            format!(", {} skipped: not finite", summary.rows_skipped)
        } else {
            String::new()
        }
    );
    Ok(())
}
