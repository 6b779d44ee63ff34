#pragma once
// Private to the pipeline (pipeline.cpp) and its test: whether its two independent parts run
// side by side.
namespace wul3d::detail {

/// Whether Pipeline::run_on's two parts (the clustering with its colours; the plane and
/// segmentation stages) run side by side on two threads: each period of frames starts with
/// a few frames each way, timed, and goes on the faster way. It pays on new scenes at
/// --decimate 2, not when the clustering is cheap (a frame repeated) nor on 640x480 frames
/// (docs/DESIGN.md). Results are the same either way; only the time differs.
class SideBySideChoice {
public:
    static constexpr int kTrials = 3;    ///< frames each way per period (the fastest counts)
    static constexpr int kPeriod = 300;  ///< frames per choice

    bool next() const;  ///< the way for the coming frame: true = side by side
    void record(bool side_by_side, double ms);  ///< the coming frame's time for the two parts

private:
    int frame_ = 0;
    double best_ms_[2] = {0, 0};  ///< [0] one after the other, [1] side by side
    bool side_by_side_ = false;
};

}  // namespace wul3d::detail
