//! `stf-lab`: the command-line program of the shear-thickening fluid lab.
//!
//! ```text
//! stf-lab models                          list models with their parameters
//! stf-lab simulate EXP.toml --out F.csv   write a synthetic record (section [simulate])
//! stf-lab fit EXP.toml --out DIR          calibrate every model of the experiment
//! stf-lab compare EXP.toml --out DIR      fit, then compare models on the regime metrics
//! stf-lab discover EXP.toml --out DIR     find, name and add the missing effect
//! stf-lab campaign C.toml --out DIR       run fit, compare or discover over many records
//! ```
//!
//! Every command takes `-q`/`--quiet`; `-o` is `--out` and `-f` is `--force`.

#![deny(clippy::unwrap_used)]

mod allocator;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use stf_lab::campaign::slurm_script::SlurmOptions;
use stf_lab::{
    campaign::command as cmd_campaign,
    commands::{
        compare as cmd_compare, discover as cmd_discover, fit as cmd_fit, models as cmd_models,
        simulate as cmd_simulate,
    },
    experiment::Experiment,
    tell,
    terminal::interrupt,
};

/// A lab for shear-thickening fluid force models: simulate, fit, compare, discover.
#[derive(Parser)]
#[command(name = "stf-lab", version, about)]
struct Cli {
    /// No progress display (before or after the command; `simulate` and `models` show none).
    #[arg(short, long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the force models (built-in and scripts) with their parameters.
    #[command(after_help = MODELS_HELP)]
    Models {
        /// Validate this script and print its parameters instead.
        #[arg(long, value_name = "SCRIPT")]
        check: Option<PathBuf>,
        /// Folder of script models to list (default: models/scripts when present).
        #[arg(long, value_name = "DIR")]
        scripts: Option<PathBuf>,
    },
    /// Write a synthetic record from the experiment's [simulate] section.
    ///
    /// `--out` is the record to write (CSV); a JSON sidecar is written beside it.
    #[command(after_help = SIMULATE_HELP)]
    Simulate(Run),
    /// Calibrate every model of the experiment against its record.
    ///
    /// `--out` is the folder for fit.json and fitted.csv (replaced as a whole).
    #[command(after_help = FIT_HELP)]
    Fit(Run),
    /// Fit every model, then compare them regime by regime.
    ///
    /// `--out` is the folder for compare.json, compare.md, compare.csv and the fit results
    /// (replaced as a whole).
    #[command(after_help = COMPARE_HELP)]
    Compare(Run),
    /// Find, name and add the effect the base model misses; show the gap shrink.
    ///
    /// The experiment needs a [discover] section; `--out` is the folder for discovery.json,
    /// the report and figures (replaced as a whole).
    #[command(after_help = DISCOVER_HELP)]
    Discover(Run),
    /// Run fit, compare or discover on every record of a campaign file, then tabulate.
    #[command(after_help = CAMPAIGN_HELP)]
    Campaign(CampaignArgs),
}

/// Where every key of an experiment file is described.
macro_rules! key_reference {
    () => {
        "Every key of an experiment file, with its default: docs/experiments.md; the bundled \
         examples are in experiments/."
    };
}

const MODELS_HELP: &str = concat!(
    "Examples:\n",
    "  stf-lab models\n",
    "  stf-lab models --check models/scripts/power_law.rhai\n\n",
    "A script model is a .rhai file with fn params() and fn force(p, t, x, v, z): \
     docs/models.md."
);

const SIMULATE_HELP: &str = concat!(
    "Example:\n",
    "  stf-lab simulate experiments/paper_sweep.toml --out sweep.csv\n\n",
    "A minimal experiment:\n",
    "  [simulate]\n",
    "  sweep = { w0 = 2.35, alpha = 0.047, t0 = 50.0, t1 = 200.0 }\n",
    "  rate = 1000.0\n\n",
    key_reference!()
);

const FIT_HELP: &str = concat!(
    "Example:\n",
    "  stf-lab fit experiments/power_law_fit.toml --out out/fit\n\n",
    "A minimal experiment:\n",
    "  [data]\n",
    "  file = \"record.csv\"        # columns t, phi, x and optionally f_stf\n",
    "  [[models]]\n",
    "  name = \"power_law\"\n",
    "  params = { K = 2.0, n = { value = 1.2, min = 1.0, max = 4.0 } }\n\n",
    key_reference!()
);

const COMPARE_HELP: &str = concat!(
    "Example:\n",
    "  stf-lab compare experiments/jamming_compare.toml --out out/compare\n\n",
    "The experiment lists two or more [[models]]; [regimes] sets the thresholds.\n\n",
    key_reference!()
);

const DISCOVER_HELP: &str = concat!(
    "Example:\n",
    "  stf-lab discover experiments/discovery.toml --out out/discover\n\n",
    "The experiment needs:\n",
    "  [discover]\n",
    "  base = \"power_law\"          # the model to start from\n\n",
    key_reference!()
);

const CAMPAIGN_HELP: &str = concat!(
    "Example:\n",
    "  stf-lab campaign experiments/campaign/campaign.toml --out out/campaign\n\n",
    "A campaign file: [campaign] experiment = \"fit.toml\", command = \"fit\", conditions = \
     [\"concentration\"], then a [[records]] table per record (file = \"r1.csv\", \
     concentration = 0.4). Its keys: docs/campaigns.md; the experiment's: \
     docs/experiments.md."
);

/// What `simulate`, `fit`, `compare` and `discover` take.
#[derive(Args)]
struct Run {
    /// The experiment file.
    experiment: PathBuf,
    /// Where the results go: simulate's record, or the command's results folder (replaced as
    /// a whole).
    #[arg(short, long)]
    out: PathBuf,
    /// Replace existing results.
    #[arg(short, long)]
    force: bool,
}

impl Run {
    /// Load the experiment and run `command` on it.
    fn with(
        self,
        quiet: bool,
        command: fn(Experiment, &Path, bool, bool) -> Result<()>,
    ) -> Result<()> {
        Experiment::load(&self.experiment)
            .and_then(|exp| command(exp, &self.out, self.force, quiet))
    }
}

/// What `campaign` takes.
#[derive(Args)]
struct CampaignArgs {
    /// The campaign file ([campaign] and [[records]]).
    campaign: PathBuf,
    /// Folder for the units' results, campaign.csv, campaign.json and the report (a rerun
    /// into it resumes: units whose inputs have not changed are skipped).
    #[arg(short, long)]
    out: PathBuf,
    /// Rerun every unit, finished or not.
    #[arg(short, long)]
    force: bool,
    /// Units run at once (default: the number of cores).
    #[arg(short, long, value_name = "N")]
    jobs: Option<usize>,
    /// Run unit N (the N-th record, from 1) alone, in this process, into DIR/units/.
    #[arg(long, value_name = "N")]
    unit: Option<usize>,
    /// Only build the table, report and [global] fit from the finished units (what the
    /// Slurm collect job runs); fails naming the units missing or failed.
    #[arg(long, conflicts_with_all = ["unit", "jobs", "force", "slurm"])]
    collect: bool,
    /// Submit the units not finished to Slurm as a job array, and a collect job after it;
    /// scripts and logs go to DIR/slurm/.
    #[arg(long, conflicts_with_all = ["unit", "jobs"])]
    slurm: bool,
    /// Slurm partition of the jobs (default: the cluster's).
    #[arg(long, value_name = "P", requires = "slurm")]
    partition: Option<String>,
    /// Slurm time limit per unit, e.g. 01:00:00 (default: the partition's).
    #[arg(long, value_name = "HH:MM:SS", requires = "slurm")]
    time: Option<String>,
    /// Slurm memory per unit, e.g. 2G (default: the cluster's).
    #[arg(long, value_name = "SIZE", requires = "slurm")]
    mem: Option<String>,
    /// Slurm account to charge (default: the user's).
    #[arg(long, value_name = "A", requires = "slurm")]
    account: Option<String>,
    /// With --slurm: print the batch scripts and sbatch commands; submit and write nothing.
    #[arg(long, requires = "slurm")]
    dry_run: bool,
}

fn main() -> ExitCode {
    allocator::keep_freed_memory();
    let cli = Cli::parse();
    interrupt::install();
    let quiet = cli.quiet;
    let result = match cli.command {
        Command::Models { check, scripts } => match check {
            Some(path) => cmd_models::check(&path),
            None => cmd_models::list(scripts.as_deref()),
        },
        Command::Simulate(run) => cmd_simulate::run(&run.experiment, &run.out, run.force),
        Command::Fit(run) => run.with(quiet, cmd_fit::run_experiment),
        Command::Compare(run) => run.with(quiet, cmd_compare::run_experiment),
        Command::Discover(run) => run.with(quiet, cmd_discover::run_experiment),
        Command::Campaign(c) => cmd_campaign::run(
            &c.campaign,
            &c.out,
            &cmd_campaign::Settings {
                force: c.force,
                quiet,
                jobs: c.jobs,
                unit: c.unit,
                collect: c.collect,
                slurm: c.slurm.then_some(cmd_campaign::SlurmSettings {
                    options: SlurmOptions {
                        partition: c.partition,
                        time: c.time,
                        mem: c.mem,
                        account: c.account,
                    },
                    dry_run: c.dry_run,
                }),
            },
        ),
    };
    let result = result.and_then(|()| {
        // What was printed must have reached its stream (`> /dev/full` is a failure).
        let _ = std::io::Write::flush(&mut std::io::stdout());
        match stf_lab::terminal::output_failure() {
            Some(failure) => Err(anyhow::anyhow!("{failure}: what was printed is incomplete")),
            None => Ok(()),
        }
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tell!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
