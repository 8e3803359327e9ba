//! Simulated range sensors on a ring around the robot (S1 §3.5, Fig. 6: 8 sensors 45° apart),
//! with a beam width and seeded Gaussian noise.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

use super::error::{MobileError, check_count, check_positive, check_range};
use super::field::{MobileField, SensorField};
use super::pose::{Point2, Pose};
use super::world::World;
use crate::Deadline;

/// Sensor ring parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeSensorParams {
    /// Number of sensors, evenly spaced, sensor 0 facing forward (default 8, S1 Fig. 6).
    pub count: usize,
    /// Largest reported gap, m, measured from the robot's rim (default 2.0; S1 gives none).
    pub max_range: f64,
    /// Opening angle of each beam, rad (default π/4 so the ring covers 360°).
    pub beam_width: f64,
    /// Rays sampled across each beam (default 5).
    pub rays_per_beam: usize,
    /// Standard deviation of additive Gaussian noise, m (default 0).
    pub noise_sigma: f64,
}

impl Default for RangeSensorParams {
    fn default() -> Self {
        Self {
            count: 8,
            max_range: 2.0,
            beam_width: PI / 4.0,
            rays_per_beam: 5,
            noise_sigma: 0.0,
        }
    }
}

impl RangeSensorParams {
    /// count ≥ 3, rays ≥ 1, positive range, beam width in [0, 2π], noise ≥ 0.
    pub fn validate(&self) -> Result<(), MobileError> {
        check_count(MobileField::Sensors(SensorField::Count), self.count, 3)?;
        check_count(
            MobileField::Sensors(SensorField::RaysPerBeam),
            self.rays_per_beam,
            1,
        )?;
        check_positive(MobileField::Sensors(SensorField::MaxRange), self.max_range)?;
        check_range(
            MobileField::Sensors(SensorField::BeamWidth),
            self.beam_width,
            0.0,
            TAU,
        )?;
        check_range(
            MobileField::Sensors(SensorField::NoiseSigma),
            self.noise_sigma,
            0.0,
            f64::MAX,
        )
    }

    /// Direction of sensor `i` in the robot frame, rad: 2π i / count (counter-clockwise).
    pub fn angle(&self, i: usize) -> f64 {
        TAU * i as f64 / self.count as f64
    }
}

/// A sensor ring with its random generator and scratch buffer.
#[derive(Clone, Debug)]
pub struct RangeSensors {
    params: RangeSensorParams,
    rng: ChaCha8Rng,
    candidates: Vec<usize>,
}

impl RangeSensors {
    /// A ring with noise drawn from ChaCha8 seeded with `seed`.
    pub fn new(params: RangeSensorParams, seed: u64) -> Result<Self, MobileError> {
        params.validate()?;
        Ok(Self {
            params,
            rng: ChaCha8Rng::seed_from_u64(seed),
            candidates: Vec::new(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &RangeSensorParams {
        &self.params
    }

    /// Fills `out` (length `count`) with gaps d_i ∈ [0, max_range] from the rim of a disc robot
    /// of radius `robot_radius` at `pose`: the minimum over the beam's rays of the ray length
    /// from the centre minus the radius, plus noise.
    pub fn sense(&mut self, world: &World, pose: Pose, robot_radius: f64, out: &mut [f64]) {
        self.sense_until(world, pose, robot_radius, out, Deadline::none());
    }

    /// [`RangeSensors::sense`], polling `deadline` before each ray cast (a
    /// ray costs O(obstacles within reach)); false when
    /// stopped early (then `out` is partly filled).
    pub fn sense_until(
        &mut self,
        world: &World,
        pose: Pose,
        robot_radius: f64,
        out: &mut [f64],
        deadline: Deadline<'_>,
    ) -> bool {
        let p = self.params;
        let o = Point2::new(pose.x, pose.y);
        let reach = p.max_range + robot_radius;
        world.nearby(o, reach, &mut self.candidates);
        for (i, d) in out.iter_mut().enumerate().take(p.count) {
            let centre = pose.theta + p.angle(i);
            let mut m = reach;
            for k in 0..p.rays_per_beam {
                // A ray costs O(obstacles nearby): ask before each.
                if deadline.expired() {
                    return false;
                }
                let off = if p.rays_per_beam == 1 {
                    0.0
                } else {
                    -0.5 * p.beam_width + p.beam_width * k as f64 / (p.rays_per_beam - 1) as f64
                };
                m = m.min(world.raycast(o, centre + off, reach, &self.candidates));
            }
            let mut g = m - robot_radius;
            if p.noise_sigma > 0.0 {
                g += p.noise_sigma * gaussian(&mut self.rng);
            }
            *d = g.clamp(0.0, p.max_range);
        }
        true
    }
}

/// Standard normal sample (Box–Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(f64::MIN_POSITIVE);
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::world::Obstacle;

    #[test]
    fn wall_ahead_is_seen_by_the_front_sensor_only() {
        // Circle radius 0.5 centred 2 m ahead; robot radius 0.2; narrow beams:
        // front gap = 2 − 0.5 − 0.2 = 1.3.
        let w = World::new(vec![Obstacle::circle(2.0, 0.0, 0.5)]).unwrap();
        let p = RangeSensorParams {
            beam_width: 0.0,
            rays_per_beam: 1,
            ..RangeSensorParams::default()
        };
        let mut s = RangeSensors::new(p, 1).unwrap();
        let mut d = [0.0; 8];
        s.sense(&w, Pose::new(0.0, 0.0, 0.0), 0.2, &mut d);
        assert!((d[0] - 1.3).abs() < 1e-12);
        for g in &d[1..] {
            assert_eq!(*g, 2.0);
        }
    }

    #[test]
    fn noise_is_deterministic_per_seed() {
        let w = World::new(vec![Obstacle::circle(1.0, 0.0, 0.2)]).unwrap();
        let p = RangeSensorParams {
            noise_sigma: 0.05,
            ..RangeSensorParams::default()
        };
        let (mut a, mut b) = (RangeSensors::new(p, 7).unwrap(), RangeSensors::new(p, 7).unwrap());
        let (mut da, mut db) = ([0.0; 8], [0.0; 8]);
        a.sense(&w, Pose::default(), 0.1, &mut da);
        b.sense(&w, Pose::default(), 0.1, &mut db);
        assert_eq!(da, db);
        assert!((da[0] - 0.7).abs() < 0.3 && da[0] != 0.7);
    }

    #[test]
    fn bad_params_are_rejected() {
        let p = RangeSensorParams {
            count: 2,
            ..RangeSensorParams::default()
        };
        assert!(RangeSensors::new(p, 0).is_err());
        let p = RangeSensorParams {
            noise_sigma: -1.0,
            ..RangeSensorParams::default()
        };
        assert!(RangeSensors::new(p, 0).is_err());
    }
}
