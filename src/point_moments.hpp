#pragma once
// Running first and second moments of 3D points, the form in which the support plane's
// regions and the objects are summed: a least-squares plane and an oriented box both come
// from the same mean and covariance.
#include <Eigen/Core>

namespace wul3d::detail {

/// Layout: count, then sums of x, y, z, then of xx, xy, xz, yy, yz, zz.
constexpr int kMoments = 10;

inline void add_moments(double* s, double x, double y, double z) {
    s[0] += 1;
    s[1] += x; s[2] += y; s[3] += z;
    s[4] += x * x; s[5] += x * y; s[6] += x * z;
    s[7] += y * y; s[8] += y * z; s[9] += z * z;
}

/// The mean of the points summed in `s` and their covariance (scatter / count).
inline void mean_and_covariance(const double* s, Eigen::Vector3d& mean, Eigen::Matrix3d& cov) {
    const double n = s[0];
    const Eigen::Vector3d c(s[1] / n, s[2] / n, s[3] / n);
    cov(0, 0) = s[4] / n - c.x() * c.x();
    cov(0, 1) = cov(1, 0) = s[5] / n - c.x() * c.y();
    cov(0, 2) = cov(2, 0) = s[6] / n - c.x() * c.z();
    cov(1, 1) = s[7] / n - c.y() * c.y();
    cov(1, 2) = cov(2, 1) = s[8] / n - c.y() * c.z();
    cov(2, 2) = s[9] / n - c.z() * c.z();
    mean = c;
}

}  // namespace wul3d::detail
