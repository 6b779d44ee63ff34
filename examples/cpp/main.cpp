// Reads a frame folder (or any input `wul3d run` reads), runs the pipeline with its default
// parameters and prints the objects of every frame: one line per object, its id, pixels,
// image box and centroid in metres.
#include <wul3d/error.hpp>
#include <wul3d/io.hpp>
#include <wul3d/pipeline.hpp>

#include <cstdio>
#include <memory>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: wul3d_example FRAME_FOLDER\n");
        return 2;
    }
    try {
        std::unique_ptr<wul3d::FrameSource> source = wul3d::open_source(argv[1], {});
        wul3d::Pipeline pipeline(wul3d::PipelineParams{});
        wul3d::SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            const wul3d::FrameResult& result =
                item.is_raw ? pipeline.process(item.raw, *source->calibration(),
                                               wul3d::RegistrationMode::DepthToColor)
                            : pipeline.process(item.frame);
            std::printf("%s: %zu objects\n", source->name(i).c_str(), result.object_list.size());
            for (const wul3d::DetectedObject& o : result.object_list)
                std::printf("object %d: %zu pixels, box %d %d %d %d, centroid %.3f %.3f %.3f m\n",
                            o.id, o.pixels, o.u_min, o.v_min, o.u_max, o.v_max,
                            double(o.centroid[0]), double(o.centroid[1]), double(o.centroid[2]));
        }
    } catch (const wul3d::Error& e) {
        std::fprintf(stderr, "wul3d_example: %s\n", e.what());
        return 1;
    }
    return 0;
}
