#pragma once
// A circle through 2D points: the rims of containers and the walls of round objects, on the
// support plane (segmentation/containers.cpp, segmentation/colour_cue.cpp), and circles about
// one centre, one per layer of a solid of revolution. Header-only: the points come from a
// visitor, so the callers map pixels to the plane without a copy, and the tests feed plain
// points.
#include <Eigen/Dense>
#include <cmath>
#include <limits>

namespace wul3d::detail {

struct Circle {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double radius = std::numeric_limits<double>::quiet_NaN();  ///< NaN when no circle fits
};

/// Algebraic least squares (Kasa): the circle minimising sum (|p - c|^2 - R^2)^2, one 3 x 3
/// solve. `for_points(visit)` calls visit(p) with each point, best centred near the origin
/// for conditioning. Biased small on a short noisy arc (its circle shrinks towards the
/// chord); fit_circle corrects it. Cost: one pass over the points.
template <class ForPoints>
Circle fit_circle_kasa(ForPoints&& for_points) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for_points([&](const Eigen::Vector2d& d) {
        const Eigen::Vector3d row(d.x(), d.y(), 1.0);
        A += row * row.transpose();
        rhs -= row * d.squaredNorm();
    });
    const Eigen::Vector3d sol = A.ldlt().solve(rhs);
    Circle c;
    c.centre = Eigen::Vector2d(-sol.x() / 2, -sol.y() / 2);
    const double R2 = c.centre.squaredNorm() - sol.z();
    if (R2 > 0 && std::isfinite(R2)) c.radius = std::sqrt(R2);
    return c;
}

/// Gauss-Newton steps of the geometric fit: from Kasa's start it settles in two or three.
constexpr int kCircleSteps = 5;

/// The geometric fit: the circle minimising sum (|p - c| - R)^2, the points' distances to
/// it, by Gauss-Newton from Kasa's circle. Unbiased where Kasa's shrinks: a bowl 21 cm
/// across, its front rim seen at 1.36 m (generated tune scene 53), came out 17 cm across
/// by Kasa and 21 cm by this. Cost: one pass over the points for Kasa, one per step.
template <class ForPoints>
Circle fit_circle(ForPoints&& for_points) {
    Circle c = fit_circle_kasa(for_points);
    if (!std::isfinite(c.radius)) return c;
    for (int step = 0; step < kCircleSteps; ++step) {
        // Residual r = |p - c| - R; its gradient in (c, R) is (-(p - c) / |p - c|, -1).
        Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
        Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
        for_points([&](const Eigen::Vector2d& p) {
            const Eigen::Vector2d d = p - c.centre;
            const double len = d.norm();
            if (!(len > 0)) return;
            const Eigen::Vector3d J(-d.x() / len, -d.y() / len, -1.0);
            JtJ += J * J.transpose();
            Jtr += J * (len - c.radius);
        });
        const Eigen::Vector3d delta = JtJ.ldlt().solve(-Jtr);
        if (!delta.allFinite()) break;
        c.centre += delta.head<2>();
        c.radius += delta.z();
    }
    if (!(c.radius > 0)) c.radius = std::numeric_limits<double>::quiet_NaN();
    return c;
}

/// Circles about one centre, one per layer: the walls of a solid of revolution (a bottle's
/// neck narrower than its body) seen on the plane its axis stands on. kLayers layers at most.
template <int kLayers>
struct CoaxialCircles {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double radius[kLayers] = {};  ///< per layer, its points' mean distance from the centre
    int count[kLayers] = {};      ///< per layer, its points
    bool fitted = false;          ///< false: the points fix no centre (all on one line, or none)
};

/// The circles about one centre that minimise sum (|p - c| - R_layer)^2. `for_points(visit)`
/// calls visit(p, layer) with each point and its layer in [0, kLayers), best centred near the
/// origin. The start is Kasa's with a constant per layer (the points and their squared
/// lengths taken less their layer's means: two unknowns, one 2 x 2 solve), then
/// Gauss-Newton steps on the centre, each layer's radius its points' mean distance (so the
/// steps move the centre along the points' directions less their layer's mean direction).
/// One layer is fit_circle's circle. Cost: 3 + kCircleSteps passes over the points.
template <int kLayers, class ForPoints>
CoaxialCircles<kLayers> fit_coaxial(ForPoints&& for_points) {
    CoaxialCircles<kLayers> fit;
    double sum_x[kLayers] = {}, sum_y[kLayers] = {}, sum_sq[kLayers] = {};
    for_points([&](const Eigen::Vector2d& p, int layer) {
        ++fit.count[layer];
        sum_x[layer] += p.x(), sum_y[layer] += p.y(), sum_sq[layer] += p.squaredNorm();
    });
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for_points([&](const Eigen::Vector2d& p, int layer) {
        const double n = fit.count[layer];
        const Eigen::Vector2d d(p.x() - sum_x[layer] / n, p.y() - sum_y[layer] / n);
        A += d * d.transpose();
        rhs -= d * (p.squaredNorm() - sum_sq[layer] / n);
    });
    fit.centre = A.ldlt().solve(rhs) / -2.0;
    if (!fit.centre.allFinite()) return fit;
    // Per layer: points, sums of the unit vectors u from the centre, of the distances d, of
    // u u^T and of u d. The Gauss-Newton step comes from these in one pass: with R_layer the
    // mean d and r = d - R_layer, the gradient of r in the centre is mean(u) - u, so
    // J^T J = sum (u u^T) - n mean(u) mean(u)^T and J^T r = R_layer sum(u) - sum(u d) per layer.
    double su_x[kLayers], su_y[kLayers], sd[kLayers], suu_xx[kLayers], suu_xy[kLayers], suu_yy[kLayers],
        sud_x[kLayers], sud_y[kLayers];
    auto layer_sums = [&] {
        for (int l = 0; l < kLayers; ++l)
            su_x[l] = su_y[l] = sd[l] = suu_xx[l] = suu_xy[l] = suu_yy[l] = sud_x[l] = sud_y[l] = 0;
        for_points([&](const Eigen::Vector2d& p, int layer) {
            const Eigen::Vector2d v = p - fit.centre;
            const double len = v.norm();
            sd[layer] += len;
            if (!(len > 0)) return;
            const double ux = v.x() / len, uy = v.y() / len;
            su_x[layer] += ux, su_y[layer] += uy;
            suu_xx[layer] += ux * ux, suu_xy[layer] += ux * uy, suu_yy[layer] += uy * uy;
            sud_x[layer] += ux * len, sud_y[layer] += uy * len;
        });
        for (int l = 0; l < kLayers; ++l) fit.radius[l] = fit.count[l] > 0 ? sd[l] / fit.count[l] : 0.0;
    };
    for (int step = 0; step < kCircleSteps; ++step) {
        layer_sums();
        Eigen::Matrix2d JtJ = Eigen::Matrix2d::Zero();
        Eigen::Vector2d Jtr = Eigen::Vector2d::Zero();
        for (int l = 0; l < kLayers; ++l) {
            if (fit.count[l] == 0) continue;
            const double n = fit.count[l];
            const Eigen::Vector2d su(su_x[l], su_y[l]);
            JtJ += Eigen::Matrix2d{{suu_xx[l], suu_xy[l]}, {suu_xy[l], suu_yy[l]}} - su * su.transpose() / n;
            Jtr += fit.radius[l] * su - Eigen::Vector2d(sud_x[l], sud_y[l]);
        }
        const Eigen::Vector2d delta = JtJ.ldlt().solve(-Jtr);
        if (!delta.allFinite()) break;
        fit.centre += delta;
    }
    layer_sums();
    fit.fitted = true;
    return fit;
}

}  // namespace wul3d::detail
