//! The rate state of [`Kinematics`](crate::Kinematics): ξ̇, ẋ, ε̇, the
//! accelerations for q̈ = 0 and the convective terms. No flag tracks them:
//! each is of the configuration and rates of the call that last wrote it
//! (a solve does not clear them), and the callers evaluate them in order
//! (solve, velocities, convective terms or accelerations).

/// Velocities and accelerations of the last rate evaluations.
pub(crate) struct Rates {
    /// ξ̇ = (q̇, u̇(t)) of the last velocity evaluation.
    pub(crate) xid: Vec<f64>,
    /// ẋ of the last [`velocities`](crate::Kinematics::velocities) (or
    /// refined) call.
    pub(crate) xd: Vec<f64>,
    /// ε̇ of the same call.
    pub(crate) epsd: Vec<f64>,
    /// ẍ for q̈ = 0: F,u ü + (F,ξξ ξ̇)ξ̇, after
    /// [`accelerations`](crate::Kinematics::accelerations).
    pub(crate) xdd0: Vec<f64>,
    /// ε̈ for q̈ = 0, after the same call.
    pub(crate) epsdd0: Vec<f64>,
    /// D,xx\[ẋ, ẋ\] of every deformation, after
    /// [`convective_terms`](crate::Kinematics::convective_terms).
    pub(crate) dxx_vv: Vec<f64>,
}

impl Rates {
    /// Zeros (rest).
    pub(crate) fn new(n_x: usize, n_eps: usize, n_xi: usize) -> Self {
        Self {
            xid: vec![0.0; n_xi],
            xd: vec![0.0; n_x],
            epsd: vec![0.0; n_eps],
            xdd0: vec![0.0; n_x],
            epsdd0: vec![0.0; n_eps],
            dxx_vv: vec![0.0; n_eps],
        }
    }
}
