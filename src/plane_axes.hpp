#pragma once
// Coordinates on a plane, shared by the plane stage (a low support's outline) and the
// segmentation rules (circles, spans, axes on the support). Private to the library.
#include <cstddef>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "wul3d/cloud.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {

/// Coordinates on a plane: e1, e2 orthogonal to its normal (a point's are its foot's).
struct PlaneAxes {
    Eigen::Vector3d e1, e2;

    explicit PlaneAxes(const Plane& pl) {
        const Eigen::Vector3d nrm(pl.nx, pl.ny, pl.nz);
        int least = 0;  // the axis least aligned with the normal: a well-conditioned cross product
        nrm.cwiseAbs().minCoeff(&least);
        e1 = nrm.cross(Eigen::Vector3d::Unit(least)).normalized();
        e2 = nrm.cross(e1);
    }
    Eigen::Vector2d operator()(double x, double y, double z) const {
        const Eigen::Vector3d X(x, y, z);
        return Eigen::Vector2d(X.dot(e1), X.dot(e2));
    }
    Eigen::Vector2d operator()(const OrganizedCloud& c, std::size_t p) const { return (*this)(c.x[p], c.y[p], c.z[p]); }
};

}  // namespace wul3d::detail
