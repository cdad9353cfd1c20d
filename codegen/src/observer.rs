//! EKF and UKF emission (being written).
