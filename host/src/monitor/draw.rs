//! The dashboard, drawn from a [`State`] and nothing else: the same state always draws the same
//! screen, which is what the snapshot tests hold it to.
//!
//! ```text
//! title: link, mode, fault
//! drive: R, ω, θd — set point against actual   │  pendulum: φ against the predicted φ0,
//!                                              │  ωp and R measured against predicted, settled
//! chart: the slow angle φ and the predicted φ0 over the last minute (at a demo's end, its table)
//! event log
//! keys: s stop (always shown), c clear fault, q quit
//! ```

use kapitza_core::rig::closed_loop::ClosedLoopR;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;

use super::state::{Link, Readings, State, HISTORY_S};
use crate::outcome::show_deg;

/// An angle in (−180°, 180°] as `predict` shows it, or a dash.
fn angle(x: Option<f64>) -> String {
    x.map_or("—".into(), show_deg)
}

/// A number with `prec` decimals, or a dash when there is none.
fn num(x: Option<f64>, prec: usize) -> String {
    x.map_or("—".into(), |v| format!("{v:.prec$}"))
}

pub fn draw(frame: &mut Frame, state: &State) {
    let [title, panels, chart, log, keys] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(9),
        Constraint::Min(6),
        Constraint::Length(6),
        Constraint::Length(1),
    ])
    .areas(frame.area());
    let readings = state.readings();
    frame.render_widget(title_line(state, readings.as_ref()), title);
    let [drive, pendulum] =
        Layout::horizontal([Constraint::Percentage(45), Constraint::Percentage(55)]).areas(panels);
    frame.render_widget(drive_panel(readings.as_ref()), drive);
    frame.render_widget(pendulum_panel(readings.as_ref()), pendulum);
    if state.summary.is_empty() {
        draw_chart(frame, chart, state);
    } else {
        let lines: Vec<Line> = state
            .summary
            .iter()
            .map(|l| Line::from(format!(" {l}")))
            .collect();
        let title = " measured against predicted (q to leave) ";
        frame.render_widget(
            Paragraph::new(lines).block(Block::bordered().title(title)),
            chart,
        );
    }
    frame.render_widget(
        log_panel(state, log.height.saturating_sub(2), log.width),
        log,
    );
    frame.render_widget(key_line(), keys);
}

fn title_line(state: &State, r: Option<&Readings>) -> Paragraph<'static> {
    let link = match &state.link {
        Link::Waiting => Span::styled("waiting for the rig", Style::new().fg(Color::Yellow)),
        Link::Up { protocol, firmware } => Span::styled(
            format!(
                "up (v{protocol}, fw {}.{}.{})",
                firmware[0], firmware[1], firmware[2]
            ),
            Style::new().fg(Color::Green),
        ),
        Link::Lost(why) => Span::styled(
            format!("LOST: {why} (reconnecting)"),
            Style::new().fg(Color::Red).add_modifier(Modifier::BOLD),
        ),
    };
    let mode = r.map_or("—", |r| r.mode);
    let mode_style = match mode {
        "running" => Style::new().fg(Color::Green),
        "faulted" => Style::new().fg(Color::Red).add_modifier(Modifier::BOLD),
        _ => Style::new(),
    };
    let mut spans = vec![
        Span::styled(" kapitza ", Style::new().add_modifier(Modifier::BOLD)),
        Span::raw("│ link: "),
        link,
        Span::raw(" │ mode: "),
        Span::styled(mode.to_string(), mode_style),
    ];
    if let Some(f) = r.and_then(|r| r.fault) {
        spans.push(Span::raw(" │ fault: "));
        spans.push(Span::styled(
            f.to_string(),
            Style::new().fg(Color::Red).add_modifier(Modifier::BOLD),
        ));
    }
    Paragraph::new(Line::from(spans))
}

/// One row of a panel: 33 columns, so both panels fit side by side in 80.
fn row(label: &str, set: String, actual: String) -> Line<'static> {
    Line::from(format!(" {label:<13}{set:>9} {actual:>9}"))
}

fn drive_panel(r: Option<&Readings>) -> Paragraph<'static> {
    let lines = vec![
        row("", "set".into(), "now".into()).style(dim()),
        row(
            "R",
            num(r.and_then(|r| r.r_target), 3),
            num(r.and_then(|r| r.r), 3),
        ),
        row(
            "ω (rad/s)",
            num(r.and_then(|r| r.omega_target), 1),
            num(r.map(|r| r.omega), 1),
        ),
        row(
            "crank (rad/s)",
            String::new(),
            num(r.map(|r| r.crank_speed), 1),
        ),
        row(
            "θd (°)",
            num(r.and_then(|r| r.drive_angle_target_deg), 1),
            num(r.map(|r| r.drive_angle_deg), 1),
        ),
        Line::from(format!(
            " commands {}",
            r.map_or("—".into(), |r| r.commands.to_string())
        )),
        Line::from(format!(
            " closed-loop R {}",
            closed_loop(r.and_then(|r| r.closed_loop))
        )),
    ];
    Paragraph::new(lines).block(Block::bordered().title(" drive "))
}

/// Closed-loop R as one phrase: off, or on with its band and rate.
pub fn closed_loop(c: Option<ClosedLoopR>) -> String {
    match c {
        None => "—".into(),
        Some(c) if !c.enabled => "off (open loop)".into(),
        Some(c) => format!("on, band ±{:.3}, ≤ {:.2}/s", c.band, c.rate_max),
    }
}

fn pendulum_panel(r: Option<&Readings>) -> Paragraph<'static> {
    let warn = Style::new().fg(Color::Red).add_modifier(Modifier::BOLD);
    let settled = match r {
        Some(r) if r.mode != "running" => Span::raw(format!("drive {}", r.mode)),
        Some(r) if r.outside_reach => Span::styled("OUTSIDE REACH (>90° from blade)", warn),
        Some(r) if r.settled => Span::styled("settled", Style::new().fg(Color::Green)),
        Some(r) if r.steady => Span::raw("settling"),
        Some(_) => Span::raw("drive changing"),
        None => Span::raw("—"),
    };
    let others = r.map_or(String::new(), |r| {
        r.other_stable_deg
            .iter()
            .map(|&d| show_deg(d))
            .collect::<Vec<_>>()
            .join(", ")
    });
    let mut status = vec![Span::raw(" "), settled];
    if !others.is_empty() {
        status.push(Span::styled(format!("  also stable {others}"), dim()));
    }
    let lines = vec![
        row("", "measured".into(), "predicted".into()).style(dim()),
        row("θ now", angle(r.map(|r| r.theta_deg)), String::new()),
        row(
            "φ slow",
            angle(r.and_then(|r| r.slow_angle_deg)),
            angle(r.and_then(|r| r.predicted_phi0_deg)),
        ),
        row(
            "φ0",
            angle(r.and_then(|r| r.equilibrium_deg)),
            angle(r.and_then(|r| r.predicted_phi0_deg)),
        ),
        row(
            "ωp (rad/s)",
            num(r.and_then(|r| r.omega_p), 3),
            num(r.and_then(|r| r.predicted_omega_p), 3),
        ),
        row(
            "R in situ",
            num(r.and_then(|r| r.r_estimate), 3),
            num(r.and_then(|r| r.r_target), 3),
        ),
        Line::from(status),
    ];
    Paragraph::new(lines).block(Block::bordered().title(" pendulum "))
}

fn draw_chart(frame: &mut Frame, area: Rect, state: &State) {
    let phi: Vec<(f64, f64)> = state.history.iter().map(|p| (p.t_s, p.phi_deg)).collect();
    let predicted: Vec<(f64, f64)> = state
        .history
        .iter()
        .filter_map(|p| Some((p.t_s, p.predicted_deg?)))
        .collect();
    let end = state
        .history
        .back()
        .map_or(HISTORY_S, |p| p.t_s.max(HISTORY_S));
    let start = end - HISTORY_S;
    let (lo, hi) = angle_bounds(phi.iter().chain(&predicted).map(|p| p.1));
    let datasets = vec![
        Dataset::default()
            .name("predicted φ0")
            .marker(Marker::Dot)
            .graph_type(GraphType::Scatter)
            .style(Style::new().fg(Color::Yellow))
            .data(&predicted),
        Dataset::default()
            .name("φ")
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::new().fg(Color::Cyan))
            .data(&phi),
    ];
    let chart = Chart::new(datasets)
        .block(Block::bordered().title(" slow angle φ (°) against rig time (s) "))
        .x_axis(
            Axis::default()
                .bounds([start, end])
                .labels([format!("{start:.0}"), format!("{end:.0}")]),
        )
        .y_axis(Axis::default().bounds([lo, hi]).labels([
            format!("{lo:.0}"),
            format!("{:.0}", (lo + hi) / 2.0),
            format!("{hi:.0}"),
        ]));
    frame.render_widget(chart, area);
}

/// The chart's angle range: the data's with 5° to spare, at least 30° tall, within the chart's
/// window of [−90°, 270°] (so a settling swing fills the chart and a rod carried over the top
/// still fits).
fn angle_bounds(points: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = points.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    if lo > hi {
        return (-90.0, 270.0);
    }
    let mid = (lo + hi) / 2.0;
    let half = ((hi - lo) / 2.0 + 5.0).max(15.0);
    let lo = (mid - half).max(-90.0);
    let hi = (mid + half).min(270.0);
    ((lo / 5.0).floor() * 5.0, (hi / 5.0).ceil() * 5.0)
}

/// The event log's last lines, each wrapped to the pane's width under its time stamp (so a long
/// line loses nothing).
fn log_panel(state: &State, rows: u16, width: u16) -> Paragraph<'static> {
    const STAMP: usize = 12;
    let text_w = usize::from(width.saturating_sub(2))
        .saturating_sub(STAMP)
        .max(10);
    let mut lines: Vec<Line> = Vec::new();
    for (t, text) in &state.log {
        let chars: Vec<char> = text.chars().collect();
        for (k, part) in chars.chunks(text_w).enumerate() {
            let part: String = part.iter().collect();
            lines.push(Line::from(if k == 0 {
                format!(" {t:7.1} s  {part}")
            } else {
                format!("{:STAMP$}{part}", "")
            }));
        }
    }
    let skip = lines.len().saturating_sub(usize::from(rows));
    Paragraph::new(lines.split_off(skip)).block(Block::bordered().title(" events "))
}

fn key_line() -> Paragraph<'static> {
    let key = Style::new().add_modifier(Modifier::REVERSED | Modifier::BOLD);
    Paragraph::new(Line::from(vec![
        Span::raw(" "),
        Span::styled(" s ", key.fg(Color::Red)),
        Span::raw(" STOP the drive   "),
        Span::styled(" c ", key),
        Span::raw(" clear fault   "),
        Span::styled(" q ", key),
        Span::raw(" quit"),
    ]))
}

fn dim() -> Style {
    Style::new().add_modifier(Modifier::DIM)
}
