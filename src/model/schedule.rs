//! Time functions: the schedules of temperature, loads and prescribed components.

use crate::math::{Real, Short};

/// A piecewise-linear function of time given by a table of `(t, value)` points with strictly increasing
/// times; constant before the first and after the last point. A single point is a constant.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TimeFunction {
    points: Vec<(Real, Real)>,
}

/// Why a time table is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScheduleError {
    /// The table has no points.
    #[error("a time table needs at least one [time, value] point")]
    Empty,
    /// A time or value is NaN or infinite.
    #[error("point {index} ([{}, {}]) is not finite", Short(*time), Short(*value))]
    NotFinite {
        /// Index of the point in the table.
        index: usize,
        /// Its time.
        time: Real,
        /// Its value.
        value: Real,
    },
    /// Times do not increase strictly.
    #[error("times must increase strictly, but point {index} has t = {} after t = {}", Short(*time), Short(*previous))]
    NotIncreasing {
        /// Index of the offending point.
        index: usize,
        /// Its time.
        time: Real,
        /// The time of the point before it.
        previous: Real,
    },
}

impl TimeFunction {
    /// The constant function `value`.
    pub fn constant(value: Real) -> Self {
        Self {
            points: vec![(0.0, value)],
        }
    }

    /// The zero function.
    pub fn zero() -> Self {
        Self::constant(0.0)
    }

    /// A piecewise-linear table; fails on an empty table, non-finite entries or times that do not increase
    /// strictly.
    pub fn try_table(points: Vec<(Real, Real)>) -> Result<Self, ScheduleError> {
        if points.is_empty() {
            return Err(ScheduleError::Empty);
        }
        for (index, &(time, value)) in points.iter().enumerate() {
            if !time.is_finite() || !value.is_finite() {
                return Err(ScheduleError::NotFinite { index, time, value });
            }
            if index > 0 {
                let previous = points[index - 1].0;
                if time <= previous {
                    return Err(ScheduleError::NotIncreasing {
                        index,
                        time,
                        previous,
                    });
                }
            }
        }
        Ok(Self { points })
    }

    /// The table points.
    pub fn points(&self) -> &[(Real, Real)] {
        &self.points
    }

    /// The value at time `t` (linear between points, constant outside the table).
    pub fn value(&self, t: Real) -> Real {
        let pts = &self.points;
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if t <= first.0 {
            return first.1;
        }
        if t >= last.0 {
            return last.1;
        }
        // First point with time > t; it exists and is not the first because first.0 < t < last.0.
        let k = pts.partition_point(|&(time, _)| time <= t);
        let (t0, v0) = pts[k - 1];
        let (t1, v1) = pts[k];
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }

    /// True when the function is identically zero.
    pub fn is_zero(&self) -> bool {
        self.points.iter().all(|&(_, v)| v == 0.0)
    }

    /// True when the function never changes.
    pub fn is_constant(&self) -> bool {
        let v0 = self.points[0].1;
        self.points.iter().all(|&(_, v)| v == v0)
    }

    /// The times where the slope may change (the table's times); time stepping lands on these.
    pub fn breakpoints(&self) -> impl Iterator<Item = Real> + '_ {
        self.points.iter().map(|&(t, _)| t)
    }

    /// The smallest and largest value over all time.
    pub fn range(&self) -> (Real, Real) {
        self.points
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &(_, v)| {
                (lo.min(v), hi.max(v))
            })
    }

    /// The same function with every value multiplied by `factor`.
    pub fn scaled(&self, factor: Real) -> Self {
        Self {
            points: self.points.iter().map(|&(t, v)| (t, v * factor)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A hand-checked table: linear between points, constant outside.
    #[test]
    fn table_interpolates_linearly_and_holds_outside() {
        let f = TimeFunction::try_table(vec![(0.0, 0.0), (1.0, 15.0), (1.75, 15.0), (2.0, 0.0)])
            .unwrap();
        assert_eq!(f.value(-1.0), 0.0);
        assert_eq!(f.value(0.5), 7.5);
        assert_eq!(f.value(1.0), 15.0);
        assert_eq!(f.value(1.5), 15.0);
        assert_eq!(f.value(1.875), 7.5);
        assert_eq!(f.value(9.0), 0.0);
        assert_eq!(f.range(), (0.0, 15.0));
        assert!(TimeFunction::constant(3.0).is_constant());
    }

    #[test]
    fn bad_tables_are_rejected() {
        assert_eq!(TimeFunction::try_table(vec![]), Err(ScheduleError::Empty));
        assert!(matches!(
            TimeFunction::try_table(vec![(0.0, 1.0), (0.0, 2.0)]),
            Err(ScheduleError::NotIncreasing { index: 1, .. })
        ));
        assert!(matches!(
            TimeFunction::try_table(vec![(0.0, Real::NAN)]),
            Err(ScheduleError::NotFinite { index: 0, .. })
        ));
    }
}
