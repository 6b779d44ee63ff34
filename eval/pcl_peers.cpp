// wul3d_pcl_peers: PCL's two classical tabletop segmentations, run on wul3d's frames for
// eval/peers.py and scored there with `wul3d eval` (docs/PEERS.md). Built only when
// cmake/Pcl.cmake finds PCL, without -march or AVX flags (Debian's PCL is generic x86-64).
//
//   wul3d_pcl_peers --method plane-euclidean|organized DATA OUT
//
// DATA is anything `wul3d run` reads as frame folders (one frame or a folder of them); for
// each frame it writes OUT/<frame>/objects.png (16-bit, 0 background, 1..n objects), the
// layout `wul3d eval OUT DATA` scores, and OUT/summary.json: per frame the compute time and the
// objects' pixel counts, and ms_per_frame_median. The time runs from the depth image in memory
// to the finished label image: no disk I/O. Every PCL class used here runs on one thread (SAC's
// OpenMP is off by default).
//
// The values are the textbook ones, fixed, not tuned on OSD:
// - plane-euclidean, as the Open3D peer in eval/peers.py: the points in wul3d's depth range
//   (0.2-4.5 m) on every 2nd pixel of every 2nd row; SACSegmentation's RANSAC plane (1 cm, at
//   most 1000 iterations, coefficients refined on the inliers: PCL's planar segmentation
//   tutorial); the points more than 1 cm above it on the camera's side (the inliers removed);
//   EuclideanClusterExtraction (2 cm, kd-tree) keeping clusters of 25 grid points or more
//   (100 input pixels, the Open3D peer's rule). Each pixel takes its 2 x 2 block's label.
// - organized, PCL's organized segmentation demo (apps/src/organized_segmentation_demo.cpp)
//   on the full 640 x 480 organized cloud, NaN outside 0.2-4.5 m: IntegralImageNormalEstimation
//   (COVARIANCE_MATRIX, max depth change factor 0.02, smoothing size 20);
//   OrganizedMultiPlaneSegmentation::segmentAndRefine (planes of more than 10000 points,
//   3 degrees, 2 cm); OrganizedConnectedComponentSegmentation with an
//   EuclideanClusterComparator (1 cm, not depth dependent) that leaves the planes out;
//   components of more than 1000 points are objects. No plane, no objects (as the demo).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/common/angles.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/euclidean_cluster_comparator.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Clock = std::chrono::steady_clock;

constexpr float kZmin = 0.2f;  // wul3d's default depth range, the Open3D peer's too
constexpr float kZmax = 4.5f;

// The point of pixel (u, v) in metres, or false outside the depth range.
bool back_project(const wul3d::RgbdFrame& f, int u, int v, pcl::PointXYZ& p) {
    const std::uint16_t d = f.depth.data[static_cast<std::size_t>(v) * f.width() + u];
    const float z = static_cast<float>(d) * f.depth.scale_m_per_unit;
    if (d == 0 || z < kZmin || z > kZmax) return false;
    const wul3d::PinholeIntrinsics& k = f.intrinsics;
    p.x = static_cast<float>((u - k.cx) * z / k.fx);
    p.y = static_cast<float>((v - k.cy) * z / k.fy);
    p.z = z;
    return true;
}

// Plane RANSAC + Euclidean clustering on the 2 x 2 grid.
wul3d::LabelImage plane_euclidean(const wul3d::RgbdFrame& f) {
    const int w = f.width(), h = f.height();
    const int gw = (w + 1) / 2, gh = (h + 1) / 2;
    Cloud::Ptr points(new Cloud);
    std::vector<int> cell;  // grid cell of each point
    for (int v = 0; v < h; v += 2)
        for (int u = 0; u < w; u += 2) {
            pcl::PointXYZ p;
            if (!back_project(f, u, v, p)) continue;
            points->push_back(p);
            cell.push_back((v / 2) * gw + u / 2);
        }

    std::vector<std::uint16_t> grid(static_cast<std::size_t>(gw) * gh, 0);
    if (points->size() >= 100) {  // the Open3D peer's lower bound
        pcl::SACSegmentation<pcl::PointXYZ> sac;
        sac.setOptimizeCoefficients(true);
        sac.setModelType(pcl::SACMODEL_PLANE);
        sac.setMethodType(pcl::SAC_RANSAC);
        sac.setDistanceThreshold(0.01);
        sac.setMaxIterations(1000);
        sac.setInputCloud(points);
        pcl::PointIndices inliers;
        pcl::ModelCoefficients plane;
        sac.segment(inliers, plane);
        if (plane.values.size() == 4 && !inliers.indices.empty()) {
            float a = plane.values[0], b = plane.values[1], c = plane.values[2],
                  d = plane.values[3];
            const float norm = std::sqrt(a * a + b * b + c * c);
            // Signed distance positive on the camera's side (the origin's distance is d).
            const float sign = d < 0 ? -1.0f / norm : 1.0f / norm;
            a *= sign, b *= sign, c *= sign, d *= sign;
            std::vector<char> is_inlier(points->size(), 0);
            for (int i : inliers.indices) is_inlier[static_cast<std::size_t>(i)] = 1;
            Cloud::Ptr above(new Cloud);
            std::vector<int> above_cell;
            for (std::size_t i = 0; i < points->size(); ++i) {
                const pcl::PointXYZ& p = (*points)[i];
                if (is_inlier[i] || a * p.x + b * p.y + c * p.z + d <= 0.01f) continue;
                above->push_back(p);
                above_cell.push_back(cell[i]);
            }
            if (!above->empty()) {
                pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
                pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
                ec.setClusterTolerance(0.02);
                ec.setMinClusterSize(25);  // 25 grid points = 100 input pixels
                ec.setMaxClusterSize(std::numeric_limits<int>::max());
                ec.setSearchMethod(tree);
                ec.setInputCloud(above);
                std::vector<pcl::PointIndices> clusters;
                ec.extract(clusters);
                const std::size_t n = std::min<std::size_t>(clusters.size(), 65535);
                for (std::size_t k = 0; k < n; ++k)
                    for (int i : clusters[k].indices)
                        grid[static_cast<std::size_t>(above_cell[static_cast<std::size_t>(i)])] =
                            static_cast<std::uint16_t>(k + 1);
            }
        }
    }

    wul3d::LabelImage out{w, h, std::vector<std::uint16_t>(static_cast<std::size_t>(w) * h)};
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u)
            out.labels[static_cast<std::size_t>(v) * w + u] =
                grid[static_cast<std::size_t>(v / 2) * gw + u / 2];
    return out;
}

// Organized multi-plane segmentation + connected components on the full organized cloud.
wul3d::LabelImage organized(const wul3d::RgbdFrame& f) {
    const int w = f.width(), h = f.height();
    Cloud::Ptr cloud(new Cloud(static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h)));
    cloud->is_dense = false;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            pcl::PointXYZ& p = cloud->at(u, v);
            if (!back_project(f, u, v, p)) p.x = p.y = p.z = nan;
        }

    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
    ne.setMaxDepthChangeFactor(0.02f);
    ne.setNormalSmoothingSize(20.0f);
    ne.setInputCloud(cloud);
    ne.compute(*normals);

    pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
    mps.setMinInliers(10000);
    mps.setAngularThreshold(pcl::deg2rad(3.0));
    mps.setDistanceThreshold(0.02);
    mps.setInputNormals(normals);
    mps.setInputCloud(cloud);
    std::vector<pcl::PlanarRegion<pcl::PointXYZ>,
                Eigen::aligned_allocator<pcl::PlanarRegion<pcl::PointXYZ>>> regions;
    std::vector<pcl::ModelCoefficients> coefficients;
    std::vector<pcl::PointIndices> plane_inliers, label_indices, boundaries;
    pcl::PointCloud<pcl::Label>::Ptr labels(new pcl::PointCloud<pcl::Label>);
    mps.segmentAndRefine(regions, coefficients, plane_inliers, labels, label_indices, boundaries);

    wul3d::LabelImage out{w, h, std::vector<std::uint16_t>(static_cast<std::size_t>(w) * h, 0)};
    if (plane_inliers.empty()) return out;

    std::set<std::uint32_t> planes;
    for (const pcl::PointIndices& p : plane_inliers)
        planes.insert((*labels)[static_cast<std::size_t>(p.indices.front())].label);
    // Since PCL 1.10 the comparator joins only points whose labels are IN its "exclude" set
    // (its doc: a label not specified is excluded), the reverse of the demo's older
    // std::vector<bool> form. So the set passed holds every label but the planes': the planes
    // are what is left out, as the demo means.
    auto keep = std::make_shared<std::set<std::uint32_t>>();
    for (std::uint32_t l = 0; l < label_indices.size(); ++l)
        if (!planes.count(l)) keep->insert(l);
    auto comparator = std::make_shared<pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>>();
    comparator->setInputCloud(cloud);
    comparator->setLabels(labels);
    comparator->setExcludeLabels(keep);
    comparator->setDistanceThreshold(0.01f, false);

    pcl::PointCloud<pcl::Label> components;
    std::vector<pcl::PointIndices> component_indices;
    pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> occ(comparator);
    occ.setInputCloud(cloud);
    occ.segment(components, component_indices);

    std::uint16_t next = 0;
    for (const pcl::PointIndices& c : component_indices) {
        if (c.indices.size() <= 1000 || next == 65535) continue;
        ++next;
        for (int i : c.indices) out.labels[static_cast<std::size_t>(i)] = next;
    }
    return out;
}

int usage() {
    std::fprintf(stderr, "usage: wul3d_pcl_peers --method plane-euclidean|organized DATA OUT\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string method, data, out;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--method" && i + 1 < argc) {
            method = argv[++i];
        } else if (a == "-h" || a == "--help") {
            usage();
            return 0;
        } else if (data.empty()) {
            data = a;
        } else if (out.empty()) {
            out = a;
        } else {
            return usage();
        }
    }
    wul3d::LabelImage (*segment)(const wul3d::RgbdFrame&) = nullptr;
    if (method == "plane-euclidean") segment = plane_euclidean;
    if (method == "organized") segment = organized;
    if (!segment || data.empty() || out.empty()) return usage();

    try {
        wul3d::SourceOptions options;
        options.format = wul3d::InputFormat::Frames;
        const std::unique_ptr<wul3d::FrameSource> source = wul3d::open_source(data, options);
        nlohmann::json frames = nlohmann::json::array();
        std::vector<double> ms;
        wul3d::SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            const wul3d::RgbdFrame& f = item.frame;
            const Clock::time_point t0 = Clock::now();
            const wul3d::LabelImage labels = segment(f);
            ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());

            std::vector<std::uint64_t> pixels;
            std::uint64_t depth_pixels = 0;
            for (std::size_t p = 0; p < labels.labels.size(); ++p) {
                depth_pixels += f.depth.data[p] != 0;
                const std::uint16_t l = labels.labels[p];
                if (l == 0) continue;
                if (pixels.size() < l) pixels.resize(l, 0);
                ++pixels[l - 1];
            }
            const std::string name = source->name(i);
            std::filesystem::create_directories(std::filesystem::path(out) / name);
            wul3d::write_label_png((std::filesystem::path(out) / name / "objects.png").string(),
                                   labels);
            frames.push_back({{"name", name},
                              {"ms", ms.back()},
                              {"objects", pixels.size()},
                              {"object_pixels", pixels},
                              {"depth_pixels", depth_pixels}});
        }
        std::vector<double> sorted = ms;
        std::sort(sorted.begin(), sorted.end());
        const std::size_t n = sorted.size();
        const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
        const nlohmann::json summary = {{"method", method},
                                        {"frames", frames},
                                        {"ms_per_frame_median", median}};
        wul3d::write_text_file((std::filesystem::path(out) / "summary.json").string(),
                               summary.dump(2) + "\n");
        std::fprintf(stderr, "wul3d_pcl_peers: %s, %zu frames, median %.2f ms per frame\n",
                     method.c_str(), n, median);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "wul3d_pcl_peers: %s\n", e.what());
        return 1;
    }
}
