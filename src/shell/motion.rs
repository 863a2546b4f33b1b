//! Keyframed translations of held vertices and obstacles: piecewise-linear, or cubic Hermite as the original
//! simulator (ARCSim) evaluates its `motions`.
//!
//! A motion is a list of keyframes (tᵢ, xᵢ) with strictly increasing times, xᵢ a translation (m) from the
//! initial placement, and optionally a velocity vᵢ (m/s) per keyframe.
//!
//! **Linear.** x(t) = xᵢ + s (xᵢ₊₁ − xᵢ) on [tᵢ, tᵢ₊₁] with s = (t − tᵢ)/(tᵢ₊₁ − tᵢ); ẋ = (xᵢ₊₁ − xᵢ)/(tᵢ₊₁ − tᵢ).
//! Keyframes carry no velocity.
//!
//! **Hermite.** With hᵢ = tᵢ₊₁ − tᵢ and the same s,
//! x(t) = (2s³ − 3s² + 1) xᵢ + (s³ − 2s² + s) hᵢ vᵢ + (−2s³ + 3s²) xᵢ₊₁ + (s³ − s²) hᵢ vᵢ₊₁,
//! ẋ(t) = [(6s² − 6s) xᵢ + (3s² − 4s + 1) hᵢ vᵢ + (6s − 6s²) xᵢ₊₁ + (3s² − 2s) hᵢ vᵢ₊₁] / hᵢ,
//! C¹ in time. A keyframe without a velocity gets one as ARCSim fills it in: zero at the first and the last
//! keyframe, the central difference (xᵢ₊₁ − xᵢ₋₁)/(tᵢ₊₁ − tᵢ₋₁) in between. A two-keyframe pull from rest is
//! therefore the smoothstep x₀ + (3s² − 2s³)(x₁ − x₀), which starts and ends at rest.
//!
//! **Outside the keyframes** (both kinds): before the first keyframe the motion is at the first keyframe's
//! translation, after the last at the last's, with zero velocity. No keyframe means no translation.
//!
//! At a keyframe time tᵢ (i inside) the position is continuous; the velocity is the one of the interval that
//! starts there (for Hermite both intervals give vᵢ).
//!
//! JSON: `{"keyframes": [[t, [x, y, z]], [t, [x, y, z], [vx, vy, vz]], …], "interpolation": "hermite"}`
//! (`"linear"` when the key is left out).

use serde::de::{self, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// How a motion interpolates between its keyframes (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// piecewise linear in time (a velocity jump at every keyframe)
    #[default]
    Linear,
    /// cubic Hermite with ARCSim's velocities (C¹ in time)
    Hermite,
}

impl Interpolation {
    fn is_linear(&self) -> bool {
        *self == Interpolation::Linear
    }
}

/// One keyframe: time (s), translation (m) and, for Hermite motions, an optional velocity (m/s).
/// JSON: `[t, [x, y, z]]` or `[t, [x, y, z], [vx, vy, vz]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    /// time t (s)
    pub time: f64,
    /// translation from the initial position (m)
    pub offset: [f64; 3],
    /// velocity at the key (m/s), Hermite only; `None`: filled in as ARCSim does (zero at the ends, central difference between)
    pub velocity: Option<[f64; 3]>,
}

impl Keyframe {
    /// A keyframe without a velocity.
    pub fn at(time: f64, offset: [f64; 3]) -> Keyframe {
        Keyframe {
            time,
            offset,
            velocity: None,
        }
    }
}

impl Serialize for Keyframe {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let n = if self.velocity.is_some() { 3 } else { 2 };
        let mut t = s.serialize_tuple(n)?;
        t.serialize_element(&self.time)?;
        t.serialize_element(&self.offset)?;
        if let Some(v) = &self.velocity {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Keyframe {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Keyframe, D::Error> {
        struct KeyVisitor;
        impl<'de> Visitor<'de> for KeyVisitor {
            type Value = Keyframe;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a keyframe [time, [x, y, z]] or [time, [x, y, z], [vx, vy, vz]]")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Keyframe, A::Error> {
                let time = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let offset = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                let velocity = seq.next_element()?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &self));
                }
                Ok(Keyframe {
                    time,
                    offset,
                    velocity,
                })
            }
        }
        d.deserialize_seq(KeyVisitor)
    }
}

/// A keyframed translation (module documentation).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    /// the keyframes, in increasing time
    pub keyframes: Vec<Keyframe>,
    /// linear (default) or cubic Hermite between keyframes
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// What is wrong with a motion's keyframes (see [`Motion::check`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MotionError {
    #[error("keyframe {index}: the time {time} is not finite")]
    /// A keyframe time that is not finite.
    Time {
        /// the keyframe (0-based)
        index: usize,
        /// its time (s)
        time: f64,
    },
    /// Keyframe times that do not increase.
    #[error("keyframe {index}: times must increase, got {time} after {previous}")]
    Order {
        /// the keyframe (0-based)
        index: usize,
        /// its time (s)
        time: f64,
        /// the previous keyframe's time (s)
        previous: f64,
    },
    #[error("keyframe {index}: the translation {offset:?} is not finite")]
    /// A translation that is not finite.
    Offset {
        /// the keyframe (0-based)
        index: usize,
        /// its translation (m)
        offset: [f64; 3],
    },
    #[error("keyframe {index}: the velocity {velocity:?} is not finite")]
    /// A velocity that is not finite.
    Velocity {
        /// the keyframe (0-based)
        index: usize,
        /// its velocity (m/s)
        velocity: [f64; 3],
    },
    #[error(
        "keyframe {index} gives a velocity, which only a Hermite motion uses (\"interpolation\": \"hermite\")"
    )]
    /// A velocity given in a linear motion.
    LinearVelocity {
        /// the keyframe (0-based)
        index: usize,
    },
}

impl Motion {
    /// A piecewise-linear motion through (time, translation) keyframes.
    pub fn linear(keys: &[(f64, [f64; 3])]) -> Motion {
        Motion {
            keyframes: keys.iter().map(|&(t, x)| Keyframe::at(t, x)).collect(),
            interpolation: Interpolation::Linear,
        }
    }

    /// A cubic Hermite motion through (time, translation) keyframes with ARCSim's velocities.
    pub fn hermite(keys: &[(f64, [f64; 3])]) -> Motion {
        Motion {
            interpolation: Interpolation::Hermite,
            ..Motion::linear(keys)
        }
    }

    /// No translation at any time.
    pub fn fixed() -> Motion {
        Motion::default()
    }

    /// Finite, strictly increasing times, finite translations and velocities, and velocities only on a Hermite
    /// motion.
    pub fn check(&self) -> Result<(), MotionError> {
        for (index, k) in self.keyframes.iter().enumerate() {
            if !k.time.is_finite() {
                return Err(MotionError::Time {
                    index,
                    time: k.time,
                });
            }
            if index > 0 {
                let previous = self.keyframes[index - 1].time;
                if k.time <= previous {
                    return Err(MotionError::Order {
                        index,
                        time: k.time,
                        previous,
                    });
                }
            }
            if !k.offset.iter().all(|x| x.is_finite()) {
                return Err(MotionError::Offset {
                    index,
                    offset: k.offset,
                });
            }
            if let Some(velocity) = k.velocity {
                if self.interpolation.is_linear() {
                    return Err(MotionError::LinearVelocity { index });
                }
                if !velocity.iter().all(|x| x.is_finite()) {
                    return Err(MotionError::Velocity { index, velocity });
                }
            }
        }
        Ok(())
    }

    /// The velocity vᵢ of every keyframe of a Hermite motion: the given one, else ARCSim's (zero at the ends,
    /// central differences inside).
    pub fn keyframe_velocities(&self) -> Vec<[f64; 3]> {
        (0..self.keyframes.len())
            .map(|i| self.keyframe_velocity(i))
            .collect()
    }

    /// The velocity of keyframe i (see [`Motion::keyframe_velocities`]).
    fn keyframe_velocity(&self, i: usize) -> [f64; 3] {
        let k = &self.keyframes;
        match k[i].velocity {
            Some(v) => v,
            None if i == 0 || i + 1 == k.len() => [0.0; 3],
            None => {
                let dt = k[i + 1].time - k[i - 1].time;
                std::array::from_fn(|c| (k[i + 1].offset[c] - k[i - 1].offset[c]) / dt)
            }
        }
    }

    /// The interval [tᵢ, tᵢ₊₁) holding t, or `None` before the first and from the last keyframe on.
    fn interval(&self, t: f64) -> Option<usize> {
        let k = &self.keyframes;
        if k.len() < 2 || t.is_nan() || t < k[0].time || t >= k[k.len() - 1].time {
            return None;
        }
        // the number of keyframes at or before t, less one
        Some(k.partition_point(|key| key.time <= t) - 1)
    }

    /// The translation outside the keyframes' span (module documentation).
    fn held(&self, t: f64) -> [f64; 3] {
        match (self.keyframes.first(), self.keyframes.last()) {
            (Some(first), _) if t.is_nan() || t <= first.time => first.offset,
            (_, Some(last)) => last.offset,
            _ => [0.0; 3],
        }
    }

    /// The translation x(t) (m).
    pub fn position(&self, t: f64) -> [f64; 3] {
        let Some(i) = self.interval(t) else {
            return self.held(t);
        };
        let (a, b) = (&self.keyframes[i], &self.keyframes[i + 1]);
        let h = b.time - a.time;
        let s = (t - a.time) / h;
        match self.interpolation {
            Interpolation::Linear => {
                std::array::from_fn(|c| a.offset[c] + s * (b.offset[c] - a.offset[c]))
            }
            Interpolation::Hermite => {
                let (va, vb) = (self.keyframe_velocity(i), self.keyframe_velocity(i + 1));
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10) = (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s);
                let (h01, h11) = (-2.0 * s3 + 3.0 * s2, s3 - s2);
                std::array::from_fn(|c| {
                    h00 * a.offset[c] + h10 * h * va[c] + h01 * b.offset[c] + h11 * h * vb[c]
                })
            }
        }
    }

    /// The weights wᵢ(t) of the keyframe offsets in the translation: x(t) = Σᵢ wᵢ(t) oᵢ + (the explicit
    /// velocities' part), the same weight for each component. Linear: 1 − s and s on the interval's ends.
    /// Hermite: h₀₀ and h₀₁ on the ends, and each end's h₁₀ h or h₁₁ h times its velocity's weights when that
    /// velocity is ARCSim's central difference (oⱼ₊₁ − oⱼ₋₁)/(tⱼ₊₁ − tⱼ₋₁); an explicit or end velocity carries
    /// no offset. Outside the keyframes, 1 on the keyframe held. dx(t)/doᵢ = wᵢ(t) (the sensitivities to a
    /// handle's keyframes, `shell::solver::Sensitivity`).
    pub fn offset_weights(&self, t: f64) -> Vec<f64> {
        let k = &self.keyframes;
        let mut w = vec![0.0; k.len()];
        let Some(i) = self.interval(t) else {
            if let Some(first) = k.first() {
                let j = if t.is_nan() || t <= first.time {
                    0
                } else {
                    k.len() - 1
                };
                w[j] = 1.0;
            }
            return w;
        };
        let h = k[i + 1].time - k[i].time;
        let s = (t - k[i].time) / h;
        match self.interpolation {
            Interpolation::Linear => {
                w[i] = 1.0 - s;
                w[i + 1] = s;
            }
            Interpolation::Hermite => {
                let (s2, s3) = (s * s, s * s * s);
                w[i] += 2.0 * s3 - 3.0 * s2 + 1.0;
                w[i + 1] += -2.0 * s3 + 3.0 * s2;
                for (j, c) in [(i, (s3 - 2.0 * s2 + s) * h), (i + 1, (s3 - s2) * h)] {
                    if k[j].velocity.is_none() && j > 0 && j + 1 < k.len() {
                        let dt = k[j + 1].time - k[j - 1].time;
                        w[j + 1] += c / dt;
                        w[j - 1] -= c / dt;
                    }
                }
            }
        }
        w
    }

    /// The velocity ẋ(t) (m/s).
    pub fn velocity(&self, t: f64) -> [f64; 3] {
        let Some(i) = self.interval(t) else {
            return [0.0; 3];
        };
        let (a, b) = (&self.keyframes[i], &self.keyframes[i + 1]);
        let h = b.time - a.time;
        let s = (t - a.time) / h;
        match self.interpolation {
            Interpolation::Linear => std::array::from_fn(|c| (b.offset[c] - a.offset[c]) / h),
            Interpolation::Hermite => {
                let (va, vb) = (self.keyframe_velocity(i), self.keyframe_velocity(i + 1));
                let s2 = s * s;
                let (d00, d10) = (6.0 * s2 - 6.0 * s, 3.0 * s2 - 4.0 * s + 1.0);
                let (d01, d11) = (6.0 * s - 6.0 * s2, 3.0 * s2 - 2.0 * s);
                std::array::from_fn(|c| {
                    (d00 * a.offset[c] + d01 * b.offset[c]) / h + d10 * va[c] + d11 * vb[c]
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn close(a: [f64; 3], b: [f64; 3]) {
        for c in 0..3 {
            assert_relative_eq!(a[c], b[c], epsilon = 1e-15, max_relative = 1e-13);
        }
    }

    /// A two-keyframe Hermite pull from rest is the smoothstep: at s = ¼ the translation is
    /// (3/16 − 2/64) d = 5/32 d and the velocity 6 s (1 − s) d / T = 9/8 d / T; at s = ½ half of d at 3/2 d/T.
    #[test]
    fn two_keyframes_make_a_smoothstep() {
        let d = [-0.02, 0.0, 0.01];
        let m = Motion::hermite(&[(0.0, [0.0; 3]), (0.25, d)]);
        close(m.position(0.0625), d.map(|x| x * 5.0 / 32.0));
        close(m.velocity(0.0625), d.map(|x| x * 9.0 / 8.0 / 0.25));
        close(m.position(0.125), d.map(|x| x * 0.5));
        close(m.velocity(0.125), d.map(|x| x * 1.5 / 0.25));
        // at rest at both ends
        close(m.velocity(0.0), [0.0; 3]);
        close(m.velocity(0.25), [0.0; 3]);
        assert!(m.velocity(0.25 - 1e-9).iter().all(|v| v.abs() < 1e-8));
        // the same keyframes linear: constant velocity
        let l = Motion::linear(&[(0.0, [0.0; 3]), (0.25, d)]);
        close(l.position(0.0625), d.map(|x| x * 0.25));
        close(l.velocity(0.2), d.map(|x| x / 0.25));
    }

    /// Three keyframes (0, 0), (1, 1), (3, 5) in x: the middle velocity is the central difference 5/3; on the
    /// first interval at s = ½: x = ½ + ⅛ · 1 · (0 − 5/3) = 7/24 (h₁₀ = ⅛, h₁₁ = −⅛), ẋ = 3/2 − ¼ · 5/3 = 13/12
    /// (∂h₀₁ = 3/2, ∂h₁₁ = −¼); on the second at s = ½: x = ½ + 5/2 + ⅛ · 2 · 5/3 = 13/4, ẋ = (3/2)(4/2) − ¼ · 5/3 = 31/12.
    #[test]
    fn inner_keyframes_take_the_central_difference() {
        let m = Motion::hermite(&[
            (0.0, [0.0; 3]),
            (1.0, [1.0, 0.0, 0.0]),
            (3.0, [5.0, 0.0, 0.0]),
        ]);
        assert_eq!(m.keyframe_velocities()[1], [5.0 / 3.0, 0.0, 0.0]);
        close(m.position(0.5), [7.0 / 24.0, 0.0, 0.0]);
        close(m.velocity(0.5), [13.0 / 12.0, 0.0, 0.0]);
        close(m.position(2.0), [41.0 / 12.0, 0.0, 0.0]);
        close(m.velocity(2.0), [31.0 / 12.0, 0.0, 0.0]);
        // continuous at the inner keyframe, in position and velocity
        close(m.position(1.0), [1.0, 0.0, 0.0]);
        close(m.velocity(1.0), [5.0 / 3.0, 0.0, 0.0]);
        assert!((m.velocity(1.0 - 1e-9)[0] - 5.0 / 3.0).abs() < 1e-7);
    }

    /// An explicit velocity replaces ARCSim's: (0, 0, v = 2) to (1, 1): at s = ½, x = ½ + ⅛ · 2 = ¾ and
    /// ẋ = 3/2 + (¾ − 1 + ¼)… = 3/2 + 2 (3/4 − 2/2 + 1) … computed: ∂h₁₀(½) = −¼, so ẋ = 3/2 − ½ = 1.
    #[test]
    fn an_explicit_velocity_is_honoured() {
        let mut m = Motion::hermite(&[(0.0, [0.0; 3]), (1.0, [1.0, 0.0, 0.0])]);
        m.keyframes[0].velocity = Some([2.0, 0.0, 0.0]);
        assert!(m.check().is_ok());
        close(m.position(0.5), [0.75, 0.0, 0.0]);
        close(m.velocity(0.5), [1.0, 0.0, 0.0]);
        close(m.velocity(0.0), [2.0, 0.0, 0.0]);
        // a velocity on a linear motion is refused
        m.interpolation = Interpolation::Linear;
        assert_eq!(m.check(), Err(MotionError::LinearVelocity { index: 0 }));
    }

    /// The translation is affine in the keyframe offsets with the weights of `offset_weights`: moving keyframe i
    /// by δ moves x(t) by wᵢ(t) δ, for linear and Hermite motions (one velocity explicit), inside and outside
    /// the keyframes.
    #[test]
    fn offset_weights_are_the_derivative_of_position() {
        let keys = [
            (0.0, [0.0, 0.1, 0.0]),
            (0.3, [0.5, 0.0, -0.2]),
            (0.7, [0.2, 0.4, 0.1]),
            (1.0, [1.0, 0.0, 0.3]),
        ];
        let mut explicit = Motion::hermite(&keys);
        explicit.keyframes[2].velocity = Some([0.3, -1.0, 2.0]);
        for m in [Motion::linear(&keys), Motion::hermite(&keys), explicit] {
            for t in [-0.5, 0.0, 0.1, 0.3, 0.45, 0.69, 0.85, 1.0, 3.0] {
                let w = m.offset_weights(t);
                assert_eq!(w.len(), keys.len());
                for i in 0..keys.len() {
                    let mut moved = m.clone();
                    moved.keyframes[i].offset[1] += 1.0;
                    let (a, b) = (m.position(t), moved.position(t));
                    assert!(
                        (b[1] - a[1] - w[i]).abs() < 1e-12,
                        "t {t} keyframe {i}: {w:?}"
                    );
                    assert!((b[0] - a[0]).abs() < 1e-15 && (b[2] - a[2]).abs() < 1e-15);
                }
            }
        }
        assert!(Motion::fixed().offset_weights(0.5).is_empty());
    }

    /// Before the first keyframe at the first translation, after the last at the last, at rest; no keyframe:
    /// no translation; one keyframe: that translation at all times.
    #[test]
    fn outside_the_keyframes_the_motion_holds() {
        let m = Motion::hermite(&[(0.5, [1.0, 2.0, 3.0]), (1.0, [4.0, 5.0, 6.0])]);
        close(m.position(0.0), [1.0, 2.0, 3.0]);
        close(m.position(-7.0), [1.0, 2.0, 3.0]);
        close(m.position(2.0), [4.0, 5.0, 6.0]);
        close(m.position(1.0), [4.0, 5.0, 6.0]);
        close(m.velocity(0.0), [0.0; 3]);
        close(m.velocity(2.0), [0.0; 3]);
        close(Motion::fixed().position(3.0), [0.0; 3]);
        let one = Motion::hermite(&[(0.2, [1.0, 0.0, 0.0])]);
        close(one.position(0.0), [1.0, 0.0, 0.0]);
        close(one.position(9.0), [1.0, 0.0, 0.0]);
        close(one.velocity(0.2), [0.0; 3]);
    }

    /// The velocity is the time derivative of the position (central differences, step 1e-6).
    #[test]
    fn velocity_is_the_derivative_of_position() {
        let mut m = Motion::hermite(&[
            (0.0, [0.0, 0.1, 0.0]),
            (0.3, [0.02, -0.1, 0.05]),
            (0.7, [0.01, 0.0, -0.02]),
            (1.0, [0.0, 0.0, 0.0]),
        ]);
        m.keyframes[2].velocity = Some([0.3, -0.2, 0.1]);
        for interpolation in [Interpolation::Hermite, Interpolation::Linear] {
            m.interpolation = interpolation;
            if interpolation == Interpolation::Linear {
                m.keyframes[2].velocity = None;
            }
            for &t in &[0.05, 0.29, 0.31, 0.5, 0.69, 0.71, 0.95] {
                let e = 1e-6;
                let (p, q) = (m.position(t + e), m.position(t - e));
                let fd: [f64; 3] = std::array::from_fn(|c| (p[c] - q[c]) / (2.0 * e));
                let v = m.velocity(t);
                for c in 0..3 {
                    assert!(
                        (fd[c] - v[c]).abs() < 1e-7,
                        "{interpolation:?} t={t} {fd:?} {v:?}"
                    );
                }
            }
        }
    }

    /// JSON: two- and three-element keyframes, `linear` by default and not written; a keyframe of the wrong
    /// shape names what a keyframe is.
    #[test]
    fn json_round_trip_and_shape_errors() {
        let m: Motion = serde_json::from_str(
            r#"{"keyframes": [[0, [0, 0, 0]], [0.25, [-0.02, 0, 0], [0, 0, 0]]], "interpolation": "hermite"}"#,
        )
        .unwrap();
        assert_eq!(m.keyframes[1].velocity, Some([0.0; 3]));
        let text = serde_json::to_string(&m).unwrap();
        assert_eq!(serde_json::from_str::<Motion>(&text).unwrap(), m);
        let l: Motion = serde_json::from_str(r#"{"keyframes": [[0, [1, 2, 3]]]}"#).unwrap();
        assert_eq!(l.interpolation, Interpolation::Linear);
        assert_eq!(
            serde_json::to_string(&l).unwrap(),
            r#"{"keyframes":[[0.0,[1.0,2.0,3.0]]]}"#
        );
        for bad in [
            r#"{"keyframes": [[0, [0, 0, 0], [1, 2]]]}"#,
            r#"{"keyframes": [[0, [0, 0, 0], [1, 2, 3], 4]]}"#,
            r#"{"keyframes": [[0]]}"#,
        ] {
            assert!(serde_json::from_str::<Motion>(bad).is_err(), "{bad}");
        }
        let e = serde_json::from_str::<Motion>(r#"{"keyframes": [[0]]}"#).unwrap_err();
        assert!(
            e.to_string().contains("a keyframe [time, [x, y, z]]"),
            "{e}"
        );
    }
}
