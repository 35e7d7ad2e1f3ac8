//! What pMarineViewer draws of the planner: its op-area and subregions as `VIEW_POLYGON`, its
//! source estimate and declarations as `VIEW_MARKER`, the points where it lost the plume as
//! `VIEW_POINT`, in the string formats of MOOS-IvP's geometry library (`x=..,y=..,label=..`
//! pairs; a posting with a label already drawn replaces that shape).
//!
//! MOOS-IvP's polygon parser returns an empty polygon for one it does not find convex (nothing is
//! drawn), so a polygon that is not convex by its rule ([`moos_convex`]) is posted as a closed
//! `VIEW_SEGLIST` (its first vertex repeated at the end) under the same label instead.
//!
//! Labels: `cpt_op_area`, `cpt_subregion_K` (K from 0), `cpt_estimate` (one marker, moved as
//! the estimate moves by more than 0.5 m), `cpt_lost_N` (N from 1: every one stays on the map,
//! posted again where the planner moves it) and `cpt_declared_N` (N from 1: every one stays).

use plumetrace_core::{Decision, PlannerEvent, Telemetry, Vec2};

/// How far the estimate moves before its marker is posted again, m.
const ESTIMATE_STEP_M: f64 = 0.5;

/// A polygon as pMarineViewer draws it: `VIEW_POLYGON` when MOOS-IvP reads it as convex, else a
/// closed `VIEW_SEGLIST` (the parser would drop it as a polygon).
pub fn polygon(points: &[[f64; 2]], label: &str, color: &str) -> (&'static str, String) {
    // The vertices as the string carries them (two decimals), as the parser reads them back.
    let mut pts: Vec<[f64; 2]> = points
        .iter()
        .map(|p| {
            let r = |v: f64| format!("{v:.2}").parse::<f64>().unwrap_or(v);
            [r(p[0]), r(p[1])]
        })
        .collect();
    let var = if moos_convex(&pts) {
        "VIEW_POLYGON"
    } else {
        pts.extend(pts.first().copied());
        "VIEW_SEGLIST"
    };
    let pts: Vec<String> = pts
        .iter()
        .map(|p| format!("{:.2},{:.2}", p[0], p[1]))
        .collect();
    (
        var,
        format!(
            "pts={{{}}},label={label},edge_color={color},vertex_color={color},vertex_size=2,edge_size=1",
            pts.join(":")
        ),
    )
}

/// Which side of the line through `a` and `b` point `c` lies on, as MOOS-IvP's
/// `XYPolygon::side` decides it (2: on the line, or `a` and `b` the same point).
fn side(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> u8 {
    if a[0] == b[0] {
        return if a[1] == b[1] || c[0] == a[0] {
            2
        } else if c[0] > a[0] {
            0
        } else {
            1
        };
    }
    let m = (b[1] - a[1]) / (b[0] - a[0]);
    let k = b[1] - m * b[0];
    let y = m * c[0] + k;
    if y > c[1] {
        0
    } else if y < c[1] {
        1
    } else {
        2
    }
}

/// Whether MOOS-IvP's `XYPolygon::determine_convexity` finds `pts` convex: at least three
/// vertices, and for every edge the other vertices not on its line all lie on one side of it
/// (and at least one is off it).
pub fn moos_convex(pts: &[[f64; 2]]) -> bool {
    let n = pts.len();
    n >= 3
        && (0..n).all(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            let mut sides = (0..n)
                .filter(|&j| j != i && j != (i + 1) % n)
                .map(|j| side(a, b, pts[j]))
                .filter(|&s| s != 2);
            match sides.next() {
                Some(first) => sides.all(|s| s == first),
                None => false,
            }
        })
}

/// A marker as `VIEW_MARKER` takes it.
pub fn marker(kind: &str, p: Vec2, label: &str, color: &str, width: f64) -> String {
    format!(
        "type={kind},x={:.2},y={:.2},label={label},color={color},width={width}",
        p.x, p.y
    )
}

/// A point as `VIEW_POINT` takes it.
pub fn point(p: Vec2, label: &str, color: &str, size: u32) -> String {
    format!(
        "x={:.2},y={:.2},label={label},vertex_color={color},vertex_size={size}",
        p.x, p.y
    )
}

/// The mission's geometry: the op-area and each subregion (see [`polygon`] for which variable).
pub fn geometry(op_area: &[[f64; 2]], subregions: &[Vec<[f64; 2]>]) -> Vec<(&'static str, String)> {
    let mut out = vec![polygon(op_area, "cpt_op_area", "yellow")];
    for (k, r) in subregions.iter().enumerate() {
        out.push(polygon(r, &format!("cpt_subregion_{k}"), "gray"));
    }
    out
}

/// The drawings a run's decisions call for, with what has been drawn so far.
#[derive(Debug, Default)]
pub struct Views {
    estimate: Option<Vec2>,
    /// Where each lost point drawn is now (`cpt_lost_N` is the N-th).
    lost: Vec<Vec2>,
    declared: u32,
}

impl Views {
    /// The postings decision `d` calls for: a new lost point or declaration, a lost point moved
    /// (posted again under its label), an estimate moved by more than 0.5 m since it was last
    /// drawn.
    pub fn of(&mut self, d: &Decision) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        for e in &d.events {
            match e {
                PlannerEvent::LostPoint { pos_m } => {
                    self.lost.push(*pos_m);
                    let label = format!("cpt_lost_{}", self.lost.len());
                    out.push(("VIEW_POINT", point(*pos_m, &label, "red", 4)));
                }
                PlannerEvent::LostPointMoved { from_m, to_m } => {
                    // The latest point drawn there, as the events' readers take it.
                    if let Some(k) = self.lost.iter().rposition(|p| p == from_m) {
                        self.lost[k] = *to_m;
                        let label = format!("cpt_lost_{}", k + 1);
                        out.push(("VIEW_POINT", point(*to_m, &label, "red", 4)));
                    }
                }
                PlannerEvent::Declared { pos_m, .. } => {
                    self.declared += 1;
                    let label = format!("cpt_declared_{}", self.declared);
                    out.push((
                        "VIEW_MARKER",
                        marker("circle", *pos_m, &label, "green", 6.0),
                    ));
                }
                _ => {}
            }
        }
        for t in &d.telemetry {
            if let Telemetry::SourceEstimate { pos_m } = t
                && pos_m.x.is_finite()
                && pos_m.y.is_finite()
                && self
                    .estimate
                    .is_none_or(|e| (e - *pos_m).norm() > ESTIMATE_STEP_M)
            {
                self.estimate = Some(*pos_m);
                out.push((
                    "VIEW_MARKER",
                    marker("diamond", *pos_m, "cpt_estimate", "orange", 4.0),
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{Command, DeclarationKind, Heading, PlanStatus, VerticalCommand};

    fn decision(events: Vec<PlannerEvent>, estimate: Option<Vec2>) -> Decision {
        let mut d = Decision::new(
            Command {
                heading: Heading::from_deg(0.0),
                speed_mps: 1.0,
                vertical: VerticalCommand::Depth(2.0),
            },
            PlanStatus::Running,
        );
        d.events = events;
        d.telemetry = estimate
            .map(|pos_m| Telemetry::SourceEstimate { pos_m })
            .into_iter()
            .collect();
        d
    }

    #[test]
    fn convexity_is_decided_as_moos_ivp_decides_it() {
        let square = [[0.0, 0.0], [0.0, 100.0], [100.0, 100.0], [100.0, 0.0]];
        assert!(moos_convex(&square), "clockwise");
        let mut ccw = square;
        ccw.reverse();
        assert!(moos_convex(&ccw), "anticlockwise");
        // A vertex on an edge's line is allowed; all on one line, or fewer than 3, is not.
        assert!(moos_convex(&[
            [0.0, 0.0],
            [50.0, 0.0],
            [100.0, 0.0],
            [100.0, 100.0]
        ]));
        assert!(!moos_convex(&[[0.0, 0.0], [50.0, 0.0], [100.0, 0.0]]));
        assert!(!moos_convex(&[[0.0, 0.0], [1.0, 1.0]]));
        // A dent, and a bow tie.
        assert!(!moos_convex(&[
            [0.0, 0.0],
            [100.0, 0.0],
            [50.0, 10.0],
            [100.0, 100.0],
            [0.0, 100.0]
        ]));
        assert!(!moos_convex(&[
            [0.0, 0.0],
            [100.0, 100.0],
            [100.0, 0.0],
            [0.0, 100.0]
        ]));
        // Rounded to the two decimals the string carries: a dent of 1 mm is gone.
        let (var, _) = polygon(
            &[[0.0, 0.0], [50.0, 0.001], [100.0, 0.0], [100.0, 100.0]],
            "x",
            "gray",
        );
        assert_eq!(var, "VIEW_POLYGON");
    }

    #[test]
    fn the_planner_is_drawn_in_pmarineviewer_strings() {
        let g = geometry(
            &[[60.0, -80.0], [460.0, -80.0], [460.0, 80.0]],
            &[vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]],
        );
        assert_eq!(
            g[0],
            (
                "VIEW_POLYGON",
                "pts={60.00,-80.00:460.00,-80.00:460.00,80.00},label=cpt_op_area,edge_color=yellow,vertex_color=yellow,vertex_size=2,edge_size=1".to_string()
            )
        );
        assert!(g[1].1.contains("label=cpt_subregion_0"), "{g:?}");
        // Not convex (an L), as MOOS-IvP's parser would drop it: a closed seglist instead.
        let ell = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 50.0],
            [50.0, 50.0],
            [50.0, 100.0],
            [0.0, 100.0],
        ];
        assert_eq!(
            polygon(&ell, "cpt_op_area", "yellow"),
            (
                "VIEW_SEGLIST",
                "pts={0.00,0.00:100.00,0.00:100.00,50.00:50.00,50.00:50.00,100.00:0.00,100.00:0.00,0.00},label=cpt_op_area,edge_color=yellow,vertex_color=yellow,vertex_size=2,edge_size=1".to_string()
            )
        );
        let mut v = Views::default();
        let lost = PlannerEvent::LostPoint {
            pos_m: Vec2::new(100.0, -2.5),
        };
        let declared = PlannerEvent::Declared {
            pos_m: Vec2::new(120.25, 3.0),
            rule: DeclarationKind::new("along_flow"),
        };
        let got = v.of(&decision(vec![lost.clone()], Some(Vec2::new(130.0, 1.0))));
        assert_eq!(
            got,
            vec![
                (
                    "VIEW_POINT",
                    "x=100.00,y=-2.50,label=cpt_lost_1,vertex_color=red,vertex_size=4".to_string()
                ),
                (
                    "VIEW_MARKER",
                    "type=diamond,x=130.00,y=1.00,label=cpt_estimate,color=orange,width=4"
                        .to_string()
                ),
            ]
        );
        // An estimate that moved 0.3 m is not posted again; a second lost point has its own
        // label; the declaration is a marker of its own.
        let got = v.of(&decision(vec![lost, declared], Some(Vec2::new(130.3, 1.0))));
        assert_eq!(
            got,
            vec![
                (
                    "VIEW_POINT",
                    "x=100.00,y=-2.50,label=cpt_lost_2,vertex_color=red,vertex_size=4".to_string()
                ),
                (
                    "VIEW_MARKER",
                    "type=circle,x=120.25,y=3.00,label=cpt_declared_1,color=green,width=6"
                        .to_string()
                ),
            ]
        );
        assert_eq!(
            v.of(&decision(vec![], Some(Vec2::new(131.0, 1.0)))).len(),
            1
        );
        // A fix moves the second lost point (the latest at that spot): posted again under its
        // label; a move from where no point is drawn posts nothing.
        let moved = PlannerEvent::LostPointMoved {
            from_m: Vec2::new(100.0, -2.5),
            to_m: Vec2::new(97.5, 1.25),
        };
        let stray = PlannerEvent::LostPointMoved {
            from_m: Vec2::new(5.0, 5.0),
            to_m: Vec2::new(6.0, 6.0),
        };
        assert_eq!(
            v.of(&decision(vec![moved.clone(), stray], None)),
            vec![(
                "VIEW_POINT",
                "x=97.50,y=1.25,label=cpt_lost_2,vertex_color=red,vertex_size=4".to_string()
            )]
        );
        // The first is still where it was saved, and moves next.
        assert_eq!(
            v.of(&decision(vec![moved], None)),
            vec![(
                "VIEW_POINT",
                "x=97.50,y=1.25,label=cpt_lost_1,vertex_color=red,vertex_size=4".to_string()
            )]
        );
    }
}
