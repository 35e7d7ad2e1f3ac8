//! Several missions flown in one environment: one spin-up and one plume for all of them.
//!
//! [`fly_shared`] takes missions of one scenario and seed whose environments are built from the
//! same settings (the caller's promise; a campaign checks it, see
//! `plumetrace_campaign::execute::share_groups`). The first mission's environment is spun up and
//! stepped once per step; every mission's fleet ([`plumetrace_sim::Fleet`]: its vehicles,
//! their random streams, its message channels, planners, observers and end conditions) steps
//! against it. A mission that ends is finished at once, in the environment as it is at its end,
//! and handed over; the environment steps until the last mission ends.
//!
//! Why this gives the bits of separate runs: an environment's state after `n` steps depends
//! only on its settings and seed, never on the vehicles (a fleet's stages take the environment
//! by shared reference: sensors and the flow under a vehicle are reads, kelp and obstacles do not
//! move), and a fleet's random streams and channels are its own, derived from the run seed and
//! the vehicle index exactly as in a world of its own. Messages never leave their fleet. So
//! every fleet sees, at every step, the environment its own world would show it, and draws the
//! same numbers. Missions whose seed or vehicle step differ from the first's cannot share its
//! clock and are flown on their own.

use crate::mission::{Flight, Mission, MissionOptions, MissionRun};
use crate::setup::{MissionError, MissionSetup};
use plumetrace_env::{EnvError, Environment};
use std::time::Instant;

/// Flies `missions` (each a setup and what to record), sharing one environment among those
/// that can share it, and calls `done(k, result)` for mission `k` (its index in `missions`) as
/// soon as it ends. Missions of another seed or vehicle step than the first's (flown alone) and
/// missions whose planners could not be built come first, in index order; the others come in
/// the order they end, those ending in the same step in index order. Each result is the one
/// [`Mission::new`], [`Mission::run`] and [`Mission::finish`] give for that mission alone,
/// except for the wall times: the shared environment's time (spin-up and steps) is split
/// evenly among the missions flying in it.
pub fn fly_shared(
    missions: Vec<(MissionSetup, MissionOptions)>,
    done: &mut dyn FnMut(usize, Result<MissionRun, MissionError>),
) {
    let mut missions = missions.into_iter().enumerate();
    let Some((first_k, (mut first, first_options))) = missions.next() else {
        return;
    };
    let (seed, dt_s) = (first.seed, first.dt_s);
    let mut joining = vec![(first_k, first_options)];
    let mut setups = Vec::new();
    for (k, (setup, options)) in missions {
        if setup.seed == seed && setup.dt_s.to_bits() == dt_s.to_bits() {
            joining.push((k, options));
            setups.push(setup);
        } else {
            done(k, fly_alone(setup, options));
        }
    }
    let started = Instant::now();
    if first.spin_up().is_err() {
        // Rare (a bad spin-up setting): each mission meets the error on its own, as it would
        // alone.
        setups.insert(0, first);
        for ((k, options), setup) in joining.into_iter().zip(setups) {
            done(k, fly_alone(setup, options));
        }
        return;
    }
    let share = started.elapsed().as_secs_f64() / joining.len() as f64;
    let mut flying: Vec<(usize, Flight)> = Vec::with_capacity(joining.len());
    let mut options = joining.into_iter();
    let Some((k, o)) = options.next() else {
        return;
    };
    // The first mission's own environment is the shared one, whether or not its planners
    // could be built.
    let (env, flight) = Flight::new(first, o, None, share);
    match flight {
        Ok(flight) => flying.push((k, flight)),
        Err(e) => done(k, Err(e)),
    }
    for ((k, o), setup) in options.zip(setups) {
        match Flight::new(setup, o, Some(&env), share).1 {
            Ok(flight) => flying.push((k, flight)),
            Err(e) => done(k, Err(e)),
        }
    }
    fly(env, flying, done);
}

/// One mission on its own.
fn fly_alone(setup: MissionSetup, options: MissionOptions) -> Result<MissionRun, MissionError> {
    let mut m = Mission::new(setup, options)?;
    m.run(&mut |_, _| {})?;
    m.finish()
}

/// Steps `env` and every flight until the last one ends.
fn fly(
    mut env: Environment,
    mut flying: Vec<(usize, Flight)>,
    done: &mut dyn FnMut(usize, Result<MissionRun, MissionError>),
) {
    while let Some((_, lead)) = flying.first() {
        // Every flight has taken the same steps of the same length: they agree on when the
        // environment is due.
        if lead.fleet().env_due() {
            let t0 = Instant::now();
            let stepped = env.step();
            let share = t0.elapsed().as_secs_f64() / flying.len() as f64;
            if let Err(error) = stepped {
                for (k, f) in flying {
                    let e = f.env_error(copy_error(&error));
                    done(k, Err(e));
                }
                return;
            }
            for (_, f) in &mut flying {
                f.add_environment_time(share);
            }
        }
        let mut still = Vec::with_capacity(flying.len());
        for (k, mut f) in flying {
            match f.step(&env) {
                Ok(None) => still.push((k, f)),
                Ok(Some(_)) => done(k, f.finish(&env)),
                Err(e) => done(k, Err(e)),
            }
        }
        flying = still;
    }
}

/// The same error again, for each mission it ends.
fn copy_error(e: &EnvError) -> EnvError {
    match e {
        EnvError::InvalidParameter { key, message } => EnvError::InvalidParameter {
            key: key.clone(),
            message: message.clone(),
        },
        EnvError::File { path, message } => EnvError::File {
            path: path.clone(),
            message: message.clone(),
        },
        EnvError::Diverged { time_s, message } => EnvError::Diverged {
            time_s: *time_s,
            message: message.clone(),
        },
    }
}
