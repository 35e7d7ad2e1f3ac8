//! Source declaration: a check run at the end of every Track-Out.

use plumetrace_core::params::Choice;
use plumetrace_core::{DeclarationKind, Heading, Vec2};
use serde::{Deserialize, Serialize};

/// The `declaration` key: which rule the AMP declares with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeclarationChoice {
    /// The field rule ([`DeclarationRule::AlongFlow`]).
    AlongFlow,
    /// The field rule with a crossflow bound ([`DeclarationRule::AlongAndCrossFlow`]).
    AlongAndCrossFlow,
}

impl Choice for DeclarationChoice {
    const ALL: &'static [Self] = &[
        DeclarationChoice::AlongFlow,
        DeclarationChoice::AlongAndCrossFlow,
    ];
}

/// The `declaration_across` key: where across the flow a lost-point rule puts the source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeclarationAcross {
    /// At the most upflow lost point (the field rule).
    MostUpflow,
    /// At the mean of the three most upflow lost points across the flow (the vehicle leaves the
    /// plume on either side of its axis).
    Mean,
}

impl Choice for DeclarationAcross {
    const ALL: &'static [Self] = &[DeclarationAcross::MostUpflow, DeclarationAcross::Mean];
}

/// Where a lost-point rule puts the source once it holds, relative to the three most upflow lost
/// points. The field rule declares the most upflow one; but a bottom source's chemical reaches a
/// vehicle at altitude only some way downflow of it, so the most upflow contact lies downflow of
/// the source by about that distance, whatever the site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// How far upflow of the most upflow lost point, m (0: at it).
    pub upflow_m: f64,
    /// Where across the flow.
    pub across: DeclarationAcross,
}

impl Placement {
    /// The field rule's placement: the most upflow lost point itself.
    pub const FIELD: Placement = Placement {
        upflow_m: 0.0,
        across: DeclarationAcross::MostUpflow,
    };
}

/// How the planner decides that the source has been found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DeclarationRule {
    /// The field rule: the three most upflow lost points lie within `along_m` of each other along
    /// the flow; the most upflow one is declared. Crossflow spread is ignored (the cause of the
    /// 31 m crossflow error at Duck).
    AlongFlow {
        /// Along-flow spread, m (4).
        along_m: f64,
    },
    /// The field rule plus a crossflow bound: the three points must also lie within `cross_m` of
    /// each other across the flow (the fix proposed after the field tests).
    AlongAndCrossFlow {
        /// Along-flow spread, m (4).
        along_m: f64,
        /// Crossflow spread, m.
        cross_m: f64,
    },
}

/// The field rule's name in events.
pub const ALONG_FLOW: DeclarationKind = DeclarationKind::new("along_flow");
/// The field rule with a crossflow bound, in events.
pub const ALONG_AND_CROSS_FLOW: DeclarationKind = DeclarationKind::new("along_and_cross_flow");
/// A multi-source search traced the plume to its subregion's up-flow edge, in events.
pub const UPFLOW_EDGE: DeclarationKind = DeclarationKind::new("upflow_edge");

impl DeclarationRule {
    /// The rule as reported in events.
    pub fn kind(&self) -> DeclarationKind {
        match self {
            DeclarationRule::AlongFlow { .. } => ALONG_FLOW,
            DeclarationRule::AlongAndCrossFlow { .. } => ALONG_AND_CROSS_FLOW,
        }
    }

    /// The declared position, if the lost points satisfy the rule for upflow direction `upflow`:
    /// the most upflow lost point (the field rule).
    pub fn check(&self, lost_points: &[Vec2], upflow: Heading) -> Option<Vec2> {
        self.check_placed(lost_points, upflow, Placement::FIELD)
    }

    /// The declared position, if the lost points satisfy the rule for upflow direction `upflow`,
    /// placed by `placement` relative to the three most upflow lost points.
    pub fn check_placed(
        &self,
        lost_points: &[Vec2],
        upflow: Heading,
        placement: Placement,
    ) -> Option<Vec2> {
        if lost_points.len() < 3 {
            return None;
        }
        let u = upflow.unit();
        let c = upflow.turned_deg(90.0).unit();
        let mut pts: Vec<Vec2> = lost_points.to_vec();
        // Most upflow first.
        pts.sort_by(|a, b| b.dot(&u).total_cmp(&a.dot(&u)));
        let top = &pts[..3];
        let along = top[0].dot(&u) - top[2].dot(&u);
        let (along_m, cross_m) = match *self {
            DeclarationRule::AlongFlow { along_m } => (along_m, f64::INFINITY),
            DeclarationRule::AlongAndCrossFlow { along_m, cross_m } => (along_m, cross_m),
        };
        let cross = top.iter().map(|p| p.dot(&c)).fold(f64::MIN, f64::max)
            - top.iter().map(|p| p.dot(&c)).fold(f64::MAX, f64::min);
        if !(along < along_m && cross < cross_m) {
            return None;
        }
        let across_shift = match placement.across {
            DeclarationAcross::MostUpflow => 0.0,
            DeclarationAcross::Mean => {
                top.iter().map(|p| p.dot(&c)).sum::<f64>() / 3.0 - top[0].dot(&c)
            }
        };
        let upflow_m = if placement.upflow_m.is_finite() {
            placement.upflow_m
        } else {
            0.0
        };
        Some(top[0] + u * upflow_m + c * across_shift)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fires_at_3_9_m_and_not_at_4_1_m() {
        // Flow towards North: upflow is South; "along" is the southward coordinate.
        let up = Heading::from_deg(180.0);
        let rule = DeclarationRule::AlongFlow { along_m: 4.0 };
        let close = [
            Vec2::new(0.0, 10.0),
            Vec2::new(3.0, 8.05),
            Vec2::new(-2.0, 6.1),
            Vec2::new(0.0, 60.0),
        ];
        assert_eq!(
            rule.check(&close, up),
            Some(Vec2::new(-2.0, 6.1)),
            "3.9 m apart declares the most upflow"
        );
        let far = [
            Vec2::new(0.0, 10.0),
            Vec2::new(3.0, 8.0),
            Vec2::new(-2.0, 5.9),
            Vec2::new(0.0, 60.0),
        ];
        assert_eq!(rule.check(&far, up), None, "4.1 m apart does not");
        assert_eq!(rule.check(&close[..2], up), None, "needs three points");
    }

    #[test]
    fn placement_moves_the_declared_point_upflow_and_to_the_mean_across() {
        // Flow towards North: upflow is South (-y); across (upflow turned 90 deg) is West (-x).
        let up = Heading::from_deg(180.0);
        let rule = DeclarationRule::AlongFlow { along_m: 6.0 };
        let pts = [
            Vec2::new(3.0, 10.0),
            Vec2::new(-3.0, 8.0),
            Vec2::new(3.0, 6.0),
            Vec2::new(0.0, 60.0),
        ];
        let field = rule.check(&pts, up);
        assert_eq!(
            field,
            Some(Vec2::new(3.0, 6.0)),
            "the field rule: the most upflow"
        );
        let placed = rule
            .check_placed(
                &pts,
                up,
                Placement {
                    upflow_m: 2.5,
                    across: DeclarationAcross::Mean,
                },
            )
            .expect("the rule holds");
        assert!((placed - Vec2::new(1.0, 3.5)).norm() < 1e-12, "{placed:?}");
        let upflow_only = rule.check_placed(
            &pts,
            up,
            Placement {
                upflow_m: 2.5,
                across: DeclarationAcross::MostUpflow,
            },
        );
        assert!((upflow_only.expect("holds") - Vec2::new(3.0, 3.5)).norm() < 1e-12);
        assert_eq!(
            rule.check_placed(&pts[..2], up, Placement::FIELD),
            None,
            "placement never makes a rule hold"
        );
    }

    #[test]
    fn crossflow_variant_also_bounds_the_spread_across() {
        let up = Heading::from_deg(180.0);
        let spread = [
            Vec2::new(0.0, 10.0),
            Vec2::new(30.0, 9.0),
            Vec2::new(-2.0, 8.0),
        ];
        assert!(
            DeclarationRule::AlongFlow { along_m: 4.0 }
                .check(&spread, up)
                .is_some()
        );
        assert!(
            DeclarationRule::AlongAndCrossFlow {
                along_m: 4.0,
                cross_m: 8.0
            }
            .check(&spread, up)
            .is_none()
        );
        let tight = [
            Vec2::new(0.0, 10.0),
            Vec2::new(3.0, 9.0),
            Vec2::new(-2.0, 8.0),
        ];
        assert_eq!(
            DeclarationRule::AlongAndCrossFlow {
                along_m: 4.0,
                cross_m: 8.0
            }
            .check(&tight, up),
            Some(Vec2::new(-2.0, 8.0))
        );
    }
}
