//! Vehicle dynamics: AUVs and surface craft driven by heading, speed and vertical commands.

use plumetrace_core::{Command, Heading, Vec2, VehicleId, VehicleKind, VerticalCommand};
use plumetrace_env::error::{require_non_negative, require_positive};
use plumetrace_env::{EnvError, SimRng};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The steepest DVL beam, deg from the vertical (beyond it a beam grazes the seabed).
pub const MAX_BEAM_ANGLE_DEG: f64 = 60.0;

/// The lowest altitude at which the DVL's beams are taken to reach the seabed, m (a DVL's
/// blanking distance): below it the footprints are placed as at this altitude.
const MIN_BEAM_ALTITUDE_M: f64 = 0.5;

/// Limits and responses of a vehicle. Defaults are the REMUS field values for an AUV.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleParams {
    /// AUV or surface craft.
    pub kind: VehicleKind,
    /// Highest water-relative speed, m/s (2 for the field AUV).
    pub max_speed_mps: f64,
    /// Highest turn rate, deg/s (10 for the field AUV).
    pub max_turn_rate_deg_s: f64,
    /// Time constant of the speed response, s.
    pub speed_time_constant_s: f64,
    /// Time constant of the depth/altitude response, s.
    pub vertical_time_constant_s: f64,
    /// Standard deviation of the altitude-keeping error, m (the field saw about +-0.7 m).
    pub altitude_error_sd_m: f64,
    /// Correlation time of the altitude-keeping error, s.
    pub altitude_error_time_s: f64,
    /// Angle of the DVL's four beams from the vertical, deg (30 for the field AUV; 0: no beams).
    /// Over a seabed that is not flat, altitude hold fits the seabed's slope to the beams'
    /// footprints and leads its depth command by the rise ahead ([`Vehicle::step_over`]).
    pub dvl_beam_angle_deg: f64,
    /// Horizontal range ahead of the forward altimeter, along the heading, m (10 for the field
    /// AUV; 0: none). Over a seabed that is not flat, altitude hold clears the seabed it sees.
    pub look_ahead_m: f64,
    /// Over a seabed that is not flat, the lowest altitude the altitude hold aims at, m (0.3
    /// for the field AUV: its altitude error is clipped there, about two sd below an altitude
    /// of 1 m; a commanded altitude below it is aimed at as it is).
    pub min_altitude_m: f64,
}

impl VehicleParams {
    /// The field AUV: 2 m/s, 10 deg/s, altitude error sd 0.35 m (+-0.7 m at two sd).
    pub fn auv() -> Self {
        VehicleParams {
            kind: VehicleKind::Auv,
            max_speed_mps: 2.0,
            max_turn_rate_deg_s: 10.0,
            speed_time_constant_s: 2.0,
            vertical_time_constant_s: 5.0,
            altitude_error_sd_m: 0.35,
            altitude_error_time_s: 60.0,
            dvl_beam_angle_deg: 30.0,
            look_ahead_m: 10.0,
            min_altitude_m: 0.3,
        }
    }

    /// A small surface craft: 1.5 m/s, 20 deg/s, stays at the surface.
    pub fn surface() -> Self {
        VehicleParams {
            kind: VehicleKind::Surface,
            max_speed_mps: 1.5,
            max_turn_rate_deg_s: 20.0,
            speed_time_constant_s: 2.0,
            vertical_time_constant_s: 1.0,
            altitude_error_sd_m: 0.0,
            altitude_error_time_s: 1.0,
            dvl_beam_angle_deg: 0.0,
            look_ahead_m: 0.0,
            min_altitude_m: 0.0,
        }
    }

    /// Checks every parameter; errors name the field (`max_speed_mps`).
    pub fn validate(&self) -> Result<(), EnvError> {
        require_positive("max_speed_mps", self.max_speed_mps)?;
        require_positive("max_turn_rate_deg_s", self.max_turn_rate_deg_s)?;
        require_positive("speed_time_constant_s", self.speed_time_constant_s)?;
        require_positive("vertical_time_constant_s", self.vertical_time_constant_s)?;
        require_non_negative("altitude_error_sd_m", self.altitude_error_sd_m)?;
        require_positive("altitude_error_time_s", self.altitude_error_time_s)?;
        require_non_negative("dvl_beam_angle_deg", self.dvl_beam_angle_deg)?;
        if self.dvl_beam_angle_deg > MAX_BEAM_ANGLE_DEG {
            return Err(EnvError::invalid(
                "dvl_beam_angle_deg",
                format!(
                    "must be <= {MAX_BEAM_ANGLE_DEG} deg from the vertical, got {}",
                    self.dvl_beam_angle_deg
                ),
            ));
        }
        require_non_negative("look_ahead_m", self.look_ahead_m)?;
        require_non_negative("min_altitude_m", self.min_altitude_m)
    }
}

/// The true state of a vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleState {
    /// Position `(east, north)`, m.
    pub pos_m: Vec2,
    /// Height above the seabed, m.
    pub z_m: f64,
    /// Compass heading.
    pub heading: Heading,
    /// Water-relative speed, m/s.
    pub speed_mps: f64,
    /// Current altitude-keeping error, m.
    pub altitude_error_m: f64,
}

/// A vehicle: its identity, limits and true state.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Identity in its world.
    pub id: VehicleId,
    /// Limits and responses.
    pub params: VehicleParams,
    /// The truth.
    pub state: VehicleState,
}

impl Vehicle {
    /// A vehicle at rest.
    pub fn new(
        id: VehicleId,
        params: VehicleParams,
        pos_m: Vec2,
        z_m: f64,
        heading: Heading,
    ) -> Self {
        Vehicle {
            id,
            params,
            state: VehicleState {
                pos_m,
                z_m,
                heading,
                speed_mps: 0.0,
                altitude_error_m: 0.0,
            },
        }
    }

    /// Ground velocity: water-relative velocity plus the current, m/s.
    pub fn ground_velocity(&self, flow_mps: Vec2) -> Vec2 {
        self.state.heading.unit() * self.state.speed_mps + flow_mps
    }

    /// Advances the vehicle by `dt_s` under `command` in a current `flow_mps`.
    ///
    /// `water_depth_m` converts depth and surface commands to heights above the seabed; without
    /// it they hold the present height. Non-finite commands are ignored (the vehicle keeps its
    /// heading and speed): the check is here, at the boundary between planner and vehicle.
    pub fn step(
        &mut self,
        command: &Command,
        flow_mps: Vec2,
        water_depth_m: Option<f64>,
        dt_s: f64,
        rng: &mut SimRng,
    ) {
        self.step_over(command, flow_mps, water_depth_m, None, dt_s, rng);
    }

    /// [`Vehicle::step`] over a seabed that is not flat: `seabed` gives the seabed's height at
    /// a position (`None`: flat at 0). Altitude hold aims at the given altitude above the
    /// seabed the vehicle sees ahead ([`seabed_ahead`]: the DVL's slope led by the depth
    /// response's time constant, and the forward altimeter), so that its first-order response
    /// (`vertical_time_constant_s`) keeps the altitude on a slope instead of lagging it by
    /// slope x speed x time constant; the world's check stops a vehicle below the seabed.
    pub fn step_over(
        &mut self,
        command: &Command,
        flow_mps: Vec2,
        water_depth_m: Option<f64>,
        seabed: Option<&dyn Fn(Vec2) -> f64>,
        dt_s: f64,
        rng: &mut SimRng,
    ) {
        let p = self.params;
        let s = &mut self.state;
        let (cmd_heading, cmd_speed) = if command.is_finite() {
            (command.heading, command.speed_mps)
        } else {
            (s.heading, s.speed_mps)
        };
        let max_turn = p.max_turn_rate_deg_s * dt_s;
        let turn = cmd_heading.diff_deg(s.heading).clamp(-max_turn, max_turn);
        let old_heading = s.heading;
        s.heading = s.heading.turned_deg(turn);
        let target_speed = cmd_speed.clamp(0.0, p.max_speed_mps);
        let old_speed = s.speed_mps;
        s.speed_mps +=
            (target_speed - s.speed_mps) * (1.0 - (-dt_s / p.speed_time_constant_s).exp());
        // Trapezoidal step of the water-relative velocity, plus the current.
        let water = (old_heading.unit() * old_speed + s.heading.unit() * s.speed_mps) * 0.5;
        s.pos_m += (water + flow_mps) * dt_s;

        let a = (-dt_s / p.altitude_error_time_s).exp();
        let n: f64 = StandardNormal.sample(rng);
        s.altitude_error_m =
            s.altitude_error_m * a + p.altitude_error_sd_m * (1.0 - a * a).sqrt() * n;
        let target_z = match (p.kind, command.vertical, water_depth_m) {
            (VehicleKind::Surface, _, Some(d)) | (_, VerticalCommand::Surface, Some(d)) => d,
            (VehicleKind::Surface, _, None) | (_, VerticalCommand::Surface, None) => s.z_m,
            (VehicleKind::Auv, VerticalCommand::Altitude(alt), _) if alt.is_finite() => {
                alt + s.altitude_error_m
            }
            (VehicleKind::Auv, VerticalCommand::Depth(dep), Some(d)) if dep.is_finite() => {
                d - dep + s.altitude_error_m
            }
            _ => s.z_m,
        };
        let target_z = match seabed {
            None => match water_depth_m {
                Some(d) => target_z.clamp(0.0, d),
                None => target_z.max(0.0),
            },
            Some(height_at) => {
                let floor = height_at(s.pos_m);
                let target_z = match (p.kind, command.vertical) {
                    (VehicleKind::Auv, VerticalCommand::Altitude(alt)) if alt.is_finite() => {
                        let ground = water + flow_mps;
                        // The error never takes the aim closer to the seabed than the vehicle's
                        // minimum altitude (nor below the commanded altitude, if lower).
                        let aim = (alt + s.altitude_error_m).max(p.min_altitude_m.min(alt));
                        seabed_ahead(&p, s, ground, floor, height_at) + aim
                    }
                    _ => target_z,
                };
                match water_depth_m {
                    Some(d) => target_z.clamp(floor.min(d), d),
                    None => target_z.max(floor),
                }
            }
        };
        s.z_m += (target_z - s.z_m) * (1.0 - (-dt_s / p.vertical_time_constant_s).exp());
    }
}

/// The seabed height altitude hold aims above, m: the higher of what the DVL and the forward
/// altimeter see ahead of the vehicle.
///
/// The DVL's four beams (Janus, at 45 deg either side of the bow and the stern, each
/// `dvl_beam_angle_deg` from the vertical) reach the seabed around the vehicle; the plane
/// through their footprints gives the seabed's slope, and the depth controller leads its
/// command by the rise along the ground velocity over its own time constant (a feedforward
/// matched to its bandwidth: on a plane slope the first-order response then keeps the
/// altitude). The forward altimeter reads the seabed `look_ahead_m` ahead along the heading;
/// the higher of the two is taken, so a wall ahead is climbed before the beams reach it. With
/// neither (a beam angle and a look-ahead of 0) this is the seabed under the vehicle.
fn seabed_ahead(
    p: &VehicleParams,
    s: &VehicleState,
    ground_mps: Vec2,
    floor: f64,
    height_at: &dyn Fn(Vec2) -> f64,
) -> f64 {
    let mut seen = floor;
    if p.dvl_beam_angle_deg > 0.0 {
        let altitude = (s.z_m - floor).max(MIN_BEAM_ALTITUDE_M);
        let reach = altitude * p.dvl_beam_angle_deg.to_radians().tan();
        let mut gradient = Vec2::zeros();
        for quarter in [45.0, 135.0, 225.0, 315.0] {
            let d = s.heading.turned_deg(quarter).unit() * reach;
            gradient += d * height_at(s.pos_m + d);
        }
        // Least squares over four footprints on a circle: sum(d d^T) = 2 reach^2 I.
        let gradient = gradient * (0.5 / (reach * reach));
        let lead = ground_mps * p.vertical_time_constant_s;
        let predicted = floor + gradient.dot(&lead);
        if predicted.is_finite() {
            seen = predicted;
        }
    }
    if p.look_ahead_m > 0.0 {
        let ahead = height_at(s.pos_m + s.heading.unit() * p.look_ahead_m);
        if ahead.is_finite() {
            seen = seen.max(ahead);
        }
    }
    seen
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_env::{StreamId, stream_rng};

    fn cmd(h: f64, v: f64, alt: f64) -> Command {
        Command {
            heading: Heading::from_deg(h),
            speed_mps: v,
            vertical: VerticalCommand::Altitude(alt),
        }
    }

    #[test]
    fn turn_rate_and_speed_are_limited() {
        let mut v = Vehicle::new(
            VehicleId(0),
            VehicleParams::auv(),
            Vec2::zeros(),
            2.0,
            Heading::NORTH,
        );
        let mut rng = stream_rng(1, StreamId::Vehicle(0));
        v.step(&cmd(90.0, 5.0, 2.0), Vec2::zeros(), None, 1.0, &mut rng);
        assert!(
            (v.state.heading.deg() - 10.0).abs() < 1e-9,
            "{}",
            v.state.heading.deg()
        );
        for _ in 0..60 {
            v.step(&cmd(90.0, 5.0, 2.0), Vec2::zeros(), None, 1.0, &mut rng);
        }
        assert!((v.state.heading.deg() - 90.0).abs() < 1e-9);
        assert!(
            v.state.speed_mps <= 2.0 && v.state.speed_mps > 1.99,
            "{}",
            v.state.speed_mps
        );
    }

    #[test]
    fn drifts_with_the_current() {
        let mut v = Vehicle::new(
            VehicleId(0),
            VehicleParams::auv(),
            Vec2::zeros(),
            2.0,
            Heading::NORTH,
        );
        let mut rng = stream_rng(1, StreamId::Vehicle(0));
        for _ in 0..100 {
            v.step(
                &cmd(0.0, 0.0, 2.0),
                Vec2::new(0.3, 0.0),
                None,
                0.1,
                &mut rng,
            );
        }
        assert!(
            (v.state.pos_m - Vec2::new(3.0, 0.0)).norm() < 1e-9,
            "{:?}",
            v.state.pos_m
        );
    }

    /// Flies an AUV at 2 m/s over `floor` for 120 s holding 2 m from `(x, 0)` on `heading`, the
    /// altitude error off; the altitude's shortfall (commanded less true) at every step after
    /// the first 60 s, or after `from` steps.
    fn shortfalls(
        params: VehicleParams,
        x: f64,
        heading: f64,
        floor: &dyn Fn(Vec2) -> f64,
        from: usize,
    ) -> Vec<f64> {
        let params = VehicleParams {
            altitude_error_sd_m: 0.0,
            ..params
        };
        let start = Vec2::new(x, 0.0);
        let mut v = Vehicle::new(
            VehicleId(0),
            params,
            start,
            floor(start) + 2.0,
            Heading::from_deg(heading),
        );
        v.state.speed_mps = 2.0;
        let mut rng = stream_rng(1, StreamId::Vehicle(0));
        let mut out = Vec::new();
        for k in 0..1200 {
            v.step_over(
                &cmd(heading, 2.0, 2.0),
                Vec2::zeros(),
                Some(200.0),
                Some(floor),
                0.1,
                &mut rng,
            );
            if k >= from {
                out.push(2.0 - (v.state.z_m - floor(v.state.pos_m)));
            }
        }
        out
    }

    /// The stated error of altitude hold on a 10 % slope at 2 m/s (docs/scenarios.md): within
    /// 0.02 m of the commanded altitude going up and going down, the altitude error off; with
    /// the DVL and the forward altimeter off it lags by slope x speed x time constant (0.99 m).
    #[test]
    fn altitude_hold_follows_a_ten_percent_slope_up_and_down_within_its_stated_error() {
        let floor = |p: Vec2| 0.1 * p.x;
        for heading in [90.0, 270.0] {
            let s = shortfalls(VehicleParams::auv(), 500.0, heading, &floor, 600);
            let worst = s.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
            assert!(worst < 0.02, "{heading}: {worst}");
        }
        let blind = VehicleParams {
            dvl_beam_angle_deg: 0.0,
            look_ahead_m: 0.0,
            ..VehicleParams::auv()
        };
        for (heading, sign) in [(90.0, 1.0), (270.0, -1.0)] {
            let s = shortfalls(blind, 500.0, heading, &floor, 600);
            let mean = s.iter().sum::<f64>() / s.len() as f64;
            // 0.1 * 2 m/s * 5 s = 1.0 m, less 0.1 * 2 * 0.1 / 2 = 0.01 m.
            assert!((mean - sign * 0.99).abs() < 0.01, "{heading}: {mean}");
        }
    }

    /// A channel's wall: flat, then a 10 % rise from x = 100 m, then flat again 8 m higher
    /// from x = 180 m, and back down going west. With the DVL's slope (with or without the
    /// forward altimeter) the vehicle never comes 0.05 m closer than its altitude; with the
    /// altimeter alone the top of the wall comes 0.36 m closer, blind its foot 0.99 m.
    #[test]
    fn altitude_hold_climbs_a_wall_it_sees() {
        let floor = |p: Vec2| (0.1 * (p.x - 100.0)).clamp(0.0, 8.0);
        let auv = VehicleParams::auv();
        let worst = |params: VehicleParams, heading: f64| {
            let x = if heading == 90.0 { 40.0 } else { 240.0 };
            let s = shortfalls(params, x, heading, &floor, 0);
            s.iter().fold(f64::NEG_INFINITY, |m, e| m.max(*e))
        };
        let dvl_only = VehicleParams {
            look_ahead_m: 0.0,
            ..auv
        };
        let altimeter_only = VehicleParams {
            dvl_beam_angle_deg: 0.0,
            ..auv
        };
        let blind = VehicleParams {
            dvl_beam_angle_deg: 0.0,
            ..dvl_only
        };
        for heading in [90.0, 270.0] {
            for params in [auv, dvl_only] {
                let w = worst(params, heading);
                assert!(w < 0.05, "{heading} {params:?}: {w}");
            }
        }
        // The altimeter alone leads the rise but stops climbing 10 m before the top.
        let w = worst(altimeter_only, 90.0);
        assert!(w > 0.3 && w < 0.4, "{w}");
        let w = worst(blind, 90.0);
        assert!(w > 0.9 && w < 1.0, "{w}");
    }

    /// Over a seabed grid the altitude error never takes the aim below `min_altitude_m`: a
    /// 1 m sd error at 1 m, for an hour over a flat grid, never brings the vehicle below 0.3 m;
    /// without the minimum it reaches the seabed.
    #[test]
    fn the_altitude_error_stops_at_the_minimum_altitude() {
        let lowest = |min_altitude_m: f64| {
            let params = VehicleParams {
                altitude_error_sd_m: 1.0,
                min_altitude_m,
                ..VehicleParams::auv()
            };
            let mut v = Vehicle::new(VehicleId(0), params, Vec2::zeros(), 1.0, Heading::NORTH);
            let mut rng = stream_rng(2, StreamId::Vehicle(0));
            let mut low = f64::INFINITY;
            for _ in 0..36_000 {
                v.step_over(
                    &cmd(0.0, 2.0, 1.0),
                    Vec2::zeros(),
                    Some(20.0),
                    Some(&|_| 0.0),
                    0.1,
                    &mut rng,
                );
                low = low.min(v.state.z_m);
            }
            low
        };
        let low = lowest(0.3);
        assert!((0.3..0.31).contains(&low), "{low}");
        assert!(lowest(0.0) < 0.01);
    }

    #[test]
    fn altitude_is_held_with_a_bounded_error() {
        let mut v = Vehicle::new(
            VehicleId(0),
            VehicleParams::auv(),
            Vec2::zeros(),
            10.0,
            Heading::NORTH,
        );
        let mut rng = stream_rng(2, StreamId::Vehicle(0));
        let mut dev = Vec::new();
        for k in 0..36_000 {
            v.step(
                &cmd(0.0, 2.0, 2.0),
                Vec2::zeros(),
                Some(20.0),
                0.1,
                &mut rng,
            );
            if k > 600 {
                dev.push(v.state.z_m - 2.0);
            }
        }
        let sd = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len() as f64).sqrt();
        assert!(sd > 0.2 && sd < 0.5, "altitude error sd {sd}");
        assert!(dev.iter().all(|d| d.abs() < 2.0));
    }

    #[test]
    fn non_finite_commands_are_ignored() {
        let mut v = Vehicle::new(
            VehicleId(0),
            VehicleParams::auv(),
            Vec2::zeros(),
            2.0,
            Heading::from_deg(30.0),
        );
        let mut rng = stream_rng(1, StreamId::Vehicle(0));
        v.step(
            &cmd(90.0, f64::NAN, 2.0),
            Vec2::zeros(),
            None,
            1.0,
            &mut rng,
        );
        assert!((v.state.heading.deg() - 30.0).abs() < 1e-9 && v.state.pos_m.x.is_finite());
    }

    #[test]
    fn surface_craft_stay_at_the_surface() {
        let mut v = Vehicle::new(
            VehicleId(1),
            VehicleParams::surface(),
            Vec2::zeros(),
            4.0,
            Heading::NORTH,
        );
        let mut rng = stream_rng(1, StreamId::Vehicle(1));
        for _ in 0..100 {
            v.step(&cmd(0.0, 1.0, 1.0), Vec2::zeros(), Some(4.0), 0.1, &mut rng);
        }
        assert!((v.state.z_m - 4.0).abs() < 1e-12);
        assert!(VehicleParams::auv().validate().is_ok());
        let bad = VehicleParams {
            max_speed_mps: -1.0,
            ..VehicleParams::auv()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .under("vehicles[0].dynamics")
                .to_string()
                .starts_with("vehicles[0].dynamics.max_speed_mps")
        );
    }
}
