//! `kapitza chart outcomes`: what a simulation of a scene ends up doing over two swept keys, and
//! `kapitza chart merge`, which joins the shards of such a map.

use anyhow::{anyhow, bail, Context, Result};
use indicatif::ProgressBar;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::options::{write_csv, Output, Size};
use crate::chart::draw::{self, pe, tint, Figure, SERIES};
use crate::chart::map::samples;
use crate::outcome::OutcomeOut;
use crate::record::{self, Share, PROGRESS_STEPS};
use crate::scene_file;
use kapitza_core::sim::{simulate, Options};

/// A map of outcomes: every cell a simulation of SCENE with two keys swept (`--set` syntax),
/// coloured by what the pendulum ends up doing, the rest angle shaded. Cells run in parallel.
///
/// For more cells than one machine manages, `--shard I/N` computes the cells whose index is I
/// modulo N (I from 0) and writes them to `outcomes-shard-I-of-N.json`; `kapitza chart merge`
/// joins the N files into exactly the chart one run gives. As a Slurm array job:
/// `sbatch --array=0-15 --wrap 'kapitza chart outcomes SCENE … --shard $SLURM_ARRAY_TASK_ID/16
/// --out shards'`, then `kapitza chart merge shards/outcomes-shard-*-of-16.json --out charts`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// The key along x and its range, KEY=FROM..TO (e.g. drive.angle_deg=0..180).
    #[arg(long, value_name = "KEY=FROM..TO", allow_hyphen_values = true)]
    pub x: Sweep,
    /// The key along y and its range, KEY=FROM..TO (e.g. drive.r=0.5..3).
    #[arg(long, value_name = "KEY=FROM..TO", allow_hyphen_values = true)]
    pub y: Sweep,
    /// Cells NxM along x and y, both ends included.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "NxM",
        default_value = "21x21"
    )]
    pub size: Size,
    /// Further overrides applied to every cell (KEY=VALUE, as in `simulate --set`).
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Compute only shard I of N (cells with index ≡ I mod N, I from 0) and write it to a file
    /// for `kapitza chart merge`.
    #[arg(allow_hyphen_values = true, long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Run even when the estimated CPU time passes the budget (an hour).
    #[arg(long)]
    pub no_budget: bool,
    #[command(flatten)]
    pub output: Output,
}

/// Joins the shards of `chart outcomes --shard` into the chart one run gives.
#[derive(Debug, Clone, clap::Args)]
pub struct MergeArgs {
    /// The shard files, all N of them.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    #[command(flatten)]
    pub output: Output,
}

/// KEY=FROM..TO.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    pub key: String,
    pub from: f64,
    pub to: f64,
}

impl std::str::FromStr for Sweep {
    type Err = String;
    fn from_str(s: &str) -> Result<Sweep, String> {
        let (key, range) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}`: expected KEY=FROM..TO, e.g. drive.r=0.5..3"))?;
        let r: super::options::Range = range.parse()?;
        Ok(Sweep {
            key: key.trim().to_string(),
            from: r.from,
            to: r.to,
        })
    }
}

/// I/N.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}`: expected I/N, e.g. 3/16"))?;
        let (index, count) = (
            i.trim()
                .parse::<usize>()
                .map_err(|_| format!("`{i}` in `{s}`: not an integer"))?,
            n.trim()
                .parse::<usize>()
                .map_err(|_| format!("`{n}` in `{s}`: not an integer"))?,
        );
        if count == 0 || index >= count {
            return Err(format!("`{s}`: expected 0 <= I < N"));
        }
        Ok(Shard { index, count })
    }
}

/// What one cell ended as.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    pub i: usize,
    pub j: usize,
    pub x: f64,
    pub y: f64,
    pub outcome: serde_json::Value,
    /// Wall time of this cell's simulation (s).
    pub wall_s: f64,
}

/// The map, whole or one shard; what `--json` prints and what a shard file holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Map {
    pub scene: String,
    pub title: String,
    pub x: Sweep,
    pub y: Sweep,
    pub nx: usize,
    pub ny: usize,
    pub sets: Vec<String>,
    pub shard: Option<Shard>,
    /// In index order (i along x, then j along y).
    pub cells: Vec<Cell>,
}

/// A bar over `n` cells that moves within each cell as its run reports progress.
fn progress(n: u64) -> ProgressBar {
    let bar = record::bar(
        n * PROGRESS_STEPS,
        "{spinner} {bar:40} {percent:>3}% of {msg} cells, {elapsed} elapsed, ETA {eta}",
    );
    bar.set_message(n.to_string());
    bar
}

/// The run options of one cell.
fn cell_options(file: &scene_file::SceneFile) -> Options {
    Options {
        method: file.method,
        format: file.format,
        out_dt: 0.0,
        seed: file.seed,
        ..Options::default()
    }
}

/// Runs the cells of the shard (all cells without one).
pub fn compute(args: &Args) -> Result<Map> {
    let name = args.scene.display().to_string();
    let (nx, ny) = (args.size.nx, args.size.ny);
    let xs = samples(args.x.from, args.x.to, nx);
    let ys = samples(args.y.from, args.y.to, ny);
    let shard = args.shard.unwrap_or(Shard { index: 0, count: 1 });
    let todo: Vec<usize> = (0..nx * ny)
        .filter(|c| c % shard.count == shard.index)
        .collect();
    // Every cell's overrides are checked before any runs, so a bad key costs nothing.
    let cell_sets = |c: usize| {
        let (i, j) = (c / ny, c % ny);
        let mut sets = args.set.clone();
        sets.push(format!("{}={}", args.x.key, xs[i]));
        sets.push(format!("{}={}", args.y.key, ys[j]));
        sets
    };
    let base = scene_file::load(&args.scene, &cell_sets(0))?;
    let last = scene_file::load(&args.scene, &cell_sets(nx * ny - 1))?;
    // The cost of the map: its corner cells' pilot estimates, their mean for every cell.
    let corners: Vec<f64> = [&base, &last]
        .iter()
        .filter_map(|f| crate::budget::simulation(&f.scene, &cell_options(f)))
        .collect();
    if !corners.is_empty() {
        let cpu = corners.iter().sum::<f64>() / corners.len() as f64 * todo.len() as f64;
        crate::budget::check(&format!("{name}: this map"), cpu, args.no_budget)?;
        crate::budget::announce(&name, cpu);
    }
    let bar = progress(todo.len() as u64);
    let cells = todo
        .par_iter()
        .map(|&c| -> Result<Cell> {
            let (i, j) = (c / ny, c % ny);
            let file = scene_file::load(&args.scene, &cell_sets(c))?;
            let options = cell_options(&file);
            let t = Instant::now();
            let mut share = Share::new(&bar);
            let report = simulate(&file.scene, &options, &mut share).map_err(|e| {
                anyhow!(
                    "{name} at {} = {}, {} = {}: {e}",
                    args.x.key,
                    xs[i],
                    args.y.key,
                    ys[j]
                )
            })?;
            let wall_s = t.elapsed().as_secs_f64();
            share.finish();
            Ok(Cell {
                i,
                j,
                x: xs[i],
                y: ys[j],
                outcome: serde_json::to_value(OutcomeOut::from(report.outcome))?,
                wall_s,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    Ok(Map {
        scene: name,
        title: base.title,
        x: args.x.clone(),
        y: args.y.clone(),
        nx,
        ny,
        sets: args.set.clone(),
        shard: args.shard,
        cells,
    })
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let dir = args.output.prepare()?;
    let start = Instant::now();
    let map = compute(args)?;
    let wall = start.elapsed().as_secs_f64();
    let cpu: f64 = map.cells.iter().map(|c| c.wall_s).sum();
    if let Some(s) = map.shard {
        let path = dir.join(format!("outcomes-shard-{}-of-{}.json", s.index, s.count));
        std::fs::write(&path, serde_json::to_vec(&map)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!(
            "{} cells in {wall:.2} s wall ({cpu:.2} s of simulation); shard written to {}",
            map.cells.len(),
            path.display()
        );
        return args.output.finish(&map, &[path], out);
    }
    eprintln!(
        "{} cells in {wall:.2} s wall, {cpu:.2} s of simulation over {} threads",
        map.cells.len(),
        rayon::current_num_threads()
    );
    let files = draw_map(dir, &map)?;
    args.output.finish(&map, &files, out)
}

/// Joins shards: the same scene, keys, ranges, size and overrides, each shard of the N once.
pub fn merge(args: &MergeArgs, out: &mut dyn Write) -> Result<()> {
    let dir = args.output.prepare()?;
    let mut maps = Vec::new();
    for p in &args.shards {
        let text = std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))?;
        let m: Map = serde_json::from_slice(&text)
            .with_context(|| format!("{} is not a shard of `chart outcomes`", p.display()))?;
        maps.push(m);
    }
    let merged = join(maps)?;
    let files = draw_map(dir, &merged)?;
    args.output.finish(&merged, &files, out)
}

/// The whole map from its shards.
pub fn join(maps: Vec<Map>) -> Result<Map> {
    let Some(first) = maps.first().cloned() else {
        bail!("no shards given");
    };
    let count = first.shard.map_or(1, |s| s.count);
    let mut seen = vec![false; count];
    let mut cells = Vec::new();
    for m in maps {
        if (&m.scene, &m.x, &m.y, m.nx, m.ny, &m.sets)
            != (
                &first.scene,
                &first.x,
                &first.y,
                first.nx,
                first.ny,
                &first.sets,
            )
        {
            bail!("the shards are of different maps (scene, keys, ranges, size or --set differ)");
        }
        let s = m
            .shard
            .ok_or_else(|| anyhow!("a whole map is not a shard"))?;
        if s.count != count || std::mem::replace(&mut seen[s.index], true) {
            bail!(
                "shard {}/{} is repeated or of a different split",
                s.index,
                s.count
            );
        }
        cells.extend(m.cells);
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        bail!("shard {missing}/{count} is missing");
    }
    cells.sort_by_key(|c| (c.i, c.j));
    Ok(Map {
        shard: None,
        cells,
        ..first
    })
}

fn draw_map(dir: &Path, map: &Map) -> Result<Vec<PathBuf>> {
    let mut files = draw::save(dir, "outcomes", &OutcomesFigure { map })?;
    files.push(write_csv(
        &dir.join("outcomes.csv"),
        &format!("{},{},kind,angle_deg,order,wall_s", map.x.key, map.y.key),
        map.cells.iter().map(|c| {
            let o = &c.outcome;
            format!(
                "{},{},{},{},{},{}",
                c.x,
                c.y,
                o["kind"].as_str().unwrap_or(""),
                o["angle_deg"]
                    .as_f64()
                    .map_or(String::new(), |v| v.to_string()),
                o["order"].as_u64().map_or(String::new(), |v| v.to_string()),
                c.wall_s
            )
        }),
    )?);
    Ok(files)
}

struct OutcomesFigure<'a> {
    map: &'a Map,
}

/// Kinds, their colours and legend names.
const KINDS: [(&str, RGBColor, &str); 7] = [
    ("rest", SERIES[0], "rest (shade: angle)"),
    ("flutter", SERIES[1], "flutter (period 2)"),
    ("subharmonic", SERIES[3], "subharmonic (order in the cell)"),
    ("rotation", SERIES[2], "rotation"),
    ("chaotic", RGBColor(60, 60, 60), "chaotic"),
    ("oscillation", SERIES[5], "undamped oscillation"),
    ("undecided", RGBColor(200, 200, 200), "undecided"),
];

fn colour(o: &serde_json::Value) -> RGBColor {
    let kind = o["kind"].as_str().unwrap_or("undecided");
    let (_, c, _) = KINDS
        .iter()
        .find(|k| k.0 == kind)
        .copied()
        .unwrap_or(KINDS[6]);
    if kind == "rest" {
        // |angle| from 0 (hanging) to 180° (inverted): tint from light to full.
        let a = o["angle_deg"].as_f64().unwrap_or(0.0).abs() / 180.0;
        return tint(c, 0.2 + 0.8 * a);
    }
    c
}

impl Figure for OutcomesFigure<'_> {
    fn title(&self) -> String {
        format!(
            "What the pendulum ends up doing, over {} and {}",
            self.map.x.key, self.map.y.key
        )
    }
    fn subtitle(&self) -> String {
        let sets = if self.map.sets.is_empty() {
            String::new()
        } else {
            format!(", with {}", self.map.sets.join(", "))
        };
        format!(
            "{} simulations of {} (\"{}\", the swept keys overridden{sets})",
            self.map.nx * self.map.ny,
            self.map.scene,
            self.map.title
        )
    }
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let m = self.map;
        let (chart_area, legend_area) = area.split_horizontally(draw::SIZE.0 - 420);
        let hx = 0.5 * (m.x.to - m.x.from) / (m.nx.max(2) - 1) as f64;
        let hy = 0.5 * (m.y.to - m.y.from) / (m.ny.max(2) - 1) as f64;
        let mut chart = ChartBuilder::on(&chart_area)
            .margin(20)
            .x_label_area_size(80)
            .y_label_area_size(110)
            .build_cartesian_2d(m.x.from - hx..m.x.to + hx, m.y.from - hy..m.y.to + hy)
            .map_err(pe)?;
        chart
            .configure_mesh()
            .x_desc(m.x.key.as_str())
            .y_desc(m.y.key.as_str())
            .axis_desc_style(("sans-serif", draw::AXIS_FONT))
            .label_style(("sans-serif", draw::TICK_FONT))
            .disable_mesh()
            .draw()
            .map_err(pe)?;
        chart
            .draw_series(m.cells.iter().map(|c| {
                Rectangle::new(
                    [(c.x - hx, c.y - hy), (c.x + hx, c.y + hy)],
                    colour(&c.outcome).filled(),
                )
            }))
            .map_err(pe)?;
        if m.nx <= 40 && m.ny <= 40 {
            for c in &m.cells {
                if let Some(n) = c.outcome["order"].as_u64() {
                    chart
                        .draw_series([Text::new(
                            n.to_string(),
                            (c.x - 0.3 * hx, c.y + 0.5 * hy),
                            ("sans-serif", draw::LEGEND_FONT).into_font().color(&WHITE),
                        )])
                        .map_err(pe)?;
                }
            }
        }
        let rest = KINDS[0].1;
        let rows = [
            (tint(rest, 0.2), "rest hanging (0°)".to_string()),
            (tint(rest, 0.6), "rest at ±108°".to_string()),
            (rest, "rest inverted (180°)".to_string()),
        ]
        .into_iter()
        .chain(KINDS[1..].iter().map(|(_, c, t)| (*c, (*t).to_string())));
        for (row, (c, text)) in rows.enumerate() {
            let y = 40 + 44 * row as i32;
            legend_area
                .draw(&Rectangle::new([(10, y), (40, y + 30)], c.filled()))
                .map_err(pe)?;
            legend_area
                .draw(&Text::new(
                    text,
                    (50, y + 4),
                    ("sans-serif", draw::LEGEND_FONT).into_font(),
                ))
                .map_err(pe)?;
        }
        Ok(())
    }
}
