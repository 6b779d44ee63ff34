// BOP scenes as downloaded (scene_camera.json with cam_K and depth_scale per image, rgb/ or
// gray/, depth/, mask_visib/IMID_GTID.png): built by the test from shipped frames;
// `wul3d run SCENE` reads each image with its own camera and depth unit, as the same frames
// read as frame folders, and `wul3d eval OUT SCENE` combines the masks into instance labels.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::expect_one_line;
using wul3d::test::run_cli;
using wul3d::test::TempDir;

// Image ids 0 and 3 (ids need not be contiguous) from two shipped scenes.
const int kIds[] = {0, 3};
const char* const kStems[] = {"000000", "000003"};
const char* const kSamples[] = {"image_0000", "image_0005"};

wul3d::RgbdFrame sample_frame(int i) {
    return wul3d::test::read_sample_frame(kSamples[i]);
}

/// The camera image i is given: the sample's, with the principal point moved for the
/// second image (cam_K may differ from image to image, as in T-LESS).
wul3d::PinholeIntrinsics camera(int i) {
    wul3d::PinholeIntrinsics K = sample_frame(i).intrinsics;
    if (i == 1) {
        K.fx += 7.5;
        K.cx -= 3.25;
    }
    return K;
}

nlohmann::json cam_json(const wul3d::PinholeIntrinsics& K, double depth_scale) {
    return {{"cam_K", {K.fx, 0.0, K.cx, 0.0, K.fy, K.cy, 0.0, 0.0, 1.0}},
            {"depth_scale", depth_scale},
            {"cam_R_w2c", {1, 0, 0, 0, 1, 0, 0, 0, 1}},
            {"cam_t_w2c", {0, 0, 0}}};
}

/// ROOT/test/000048, a scene of two images. `depth_scale` (mm per unit) of the second:
/// its depth.png holds the sample's millimetres divided by it.
fs::path make_scene(const fs::path& root, double depth_scale = 1.0) {
    const fs::path scene = root / "test" / "000048";
    for (const char* sub : {"rgb", "depth", "mask_visib"}) fs::create_directories(scene / sub);
    nlohmann::json cameras = nlohmann::json::object();
    for (int i = 0; i < 2; ++i) {
        wul3d::RgbdFrame f = sample_frame(i);
        const double scale = i == 1 ? depth_scale : 1.0;
        for (std::uint16_t& d : f.depth.data) d = static_cast<std::uint16_t>(d / scale);
        const std::string png = std::string(kStems[i]) + ".png";
        wul3d::write_depth_png((scene / "depth" / png).string(), f.depth);
        wul3d::write_color_png((scene / "rgb" / png).string(), f.color);
        cameras[std::to_string(kIds[i])] = cam_json(camera(i), scale);
    }
    wul3d::test::write_text(scene / "scene_camera.json", cameras.dump(1));
    return scene;
}

TEST(Bop, EachImageReadsWithItsOwnCameraAndDepthUnit) {
    TempDir tmp;
    const fs::path scene = make_scene(tmp.path(), 0.5);
    auto source = wul3d::open_source(scene.string(), {});
    ASSERT_EQ(source->size(), 2u);
    EXPECT_EQ(source->format(), wul3d::InputFormat::Bop);
    wul3d::SourceItem item;
    for (int i = 0; i < 2; ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(source->name(i), kStems[i]);
        source->read(i, item);
        const wul3d::RgbdFrame want = sample_frame(i);
        const wul3d::PinholeIntrinsics K = camera(i);
        EXPECT_EQ(item.frame.intrinsics.fx, K.fx);
        EXPECT_EQ(item.frame.intrinsics.fy, K.fy);
        EXPECT_EQ(item.frame.intrinsics.cx, K.cx);
        EXPECT_EQ(item.frame.intrinsics.cy, K.cy);
        EXPECT_EQ(item.frame.intrinsics.width, 640);
        EXPECT_EQ(item.frame.color.rgb, want.color.rgb);
        // Depth in metres: units x depth_scale / 1000, to float precision.
        ASSERT_EQ(item.frame.depth.data.size(), want.depth.data.size());
        double worst = 0.0;
        for (std::size_t p = 0; p < want.depth.data.size(); ++p) {
            const double got = item.frame.depth.data[p] * double(item.frame.depth.scale_m_per_unit);
            worst = std::max(worst, std::abs(got - want.depth.data[p] * 0.001));
        }
        EXPECT_LE(worst, 1e-5);
    }
}

TEST(Bop, GrayImagesAreTheColour) {
    TempDir tmp;
    const fs::path scene = make_scene(tmp.path());
    fs::remove_all(scene / "rgb");
    fs::create_directories(scene / "gray");
    std::vector<std::uint8_t> grey(640 * 480);
    // write_mask_png writes 0 or 255.
    for (std::size_t p = 0; p < grey.size(); ++p) grey[p] = p % 3 == 0 ? 255 : 0;
    for (const char* stem : kStems)
        wul3d::write_mask_png((scene / "gray" / (std::string(stem) + ".png")).string(), 640, 480, grey);
    wul3d::SourceItem item;
    wul3d::open_source(scene.string(), {})->read(1, item);
    ASSERT_EQ(item.frame.color.rgb.size(), 3 * grey.size());
    for (std::size_t p : {999, 1000, 1001}) {
        EXPECT_EQ(item.frame.color.rgb[3 * p + 0], grey[p]);
        EXPECT_EQ(item.frame.color.rgb[3 * p + 2], grey[p]);
    }
}

TEST(Bop, MasksCombineIntoInstanceLabelsTheFirstWinning) {
    TempDir tmp;
    const fs::path dir = tmp / "mask_visib";
    fs::create_directories(dir);
    // Three masks of image 7, gt ids 0, 1 and 2: 0 and 2 overlap in column 2.
    const int w = 6, h = 2;
    const std::vector<std::vector<std::uint8_t>> masks = {
        {255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0},
        {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},  // an object hidden from view: no pixel
        {0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1, 0}};
    for (int g = 0; g < 3; ++g)
        wul3d::write_mask_png((dir / ("000007_00000" + std::to_string(g) + ".png")).string(), w, h,
                              masks[g]);
    wul3d::write_mask_png((dir / "000009_000000.png").string(), w, h, masks[2]);
    const std::vector<wul3d::BopImageMasks> images = wul3d::list_bop_masks(tmp.path().string());
    ASSERT_EQ(images.size(), 2u);
    EXPECT_EQ(images[0].name, "000007");
    EXPECT_EQ(images[0].gt_ids, (std::vector<int>{0, 1, 2}));
    const wul3d::LabelImage l = wul3d::combine_bop_masks(images[0]);
    EXPECT_EQ(l.width, w);
    EXPECT_EQ(l.labels, (std::vector<std::uint16_t>{1, 1, 1, 3, 3, 0, 1, 1, 1, 3, 3, 0}));

    wul3d::write_mask_png((dir / "000007_000001.png").string(), 3, 4, std::vector<std::uint8_t>(12));
    EXPECT_THROW(wul3d::combine_bop_masks(wul3d::list_bop_masks(tmp.path().string())[0]),
                 wul3d::InputError);
    fs::remove_all(dir);
    EXPECT_THROW(wul3d::list_bop_masks(tmp.path().string()), wul3d::InputError);
}

TEST(Bop, RunAndEvalTakeTheSceneAsTheSameFramesInFolders) {
    TempDir tmp;
    const fs::path scene = make_scene(tmp.path());
    const fs::path out = tmp / "out";
    const auto run = run_cli({"run", scene.string(), "--out", out.string()});
    ASSERT_EQ(run.exit_code, 0) << wul3d::test::describe(run);

    // The same frames as frame folders, each with its camera: the same objects.
    const fs::path plain = tmp / "plain", plain_out = tmp / "plain_out";
    for (int i = 0; i < 2; ++i) {
        wul3d::RgbdFrame f = sample_frame(i);
        f.intrinsics = camera(i);
        wul3d::write_frame_folder((plain / kStems[i]).string(), f);
    }
    const auto run_plain = run_cli({"run", plain.string(), "--out", plain_out.string()});
    ASSERT_EQ(run_plain.exit_code, 0) << wul3d::test::describe(run_plain);
    for (const char* stem : kStems) {
        const std::string got = wul3d::test::slurp(out / stem / "objects.png");
        ASSERT_FALSE(got.empty()) << stem;
        EXPECT_EQ(got, wul3d::test::slurp(plain_out / stem / "objects.png")) << stem;
    }

    // mask_visib/ as BOP would mask the run's own objects, in reverse order of their ids
    // (gt ids are BOP's, not ours): a perfect score.
    for (const char* stem : kStems) {
        const wul3d::LabelImage objects = wul3d::read_label_png((out / stem / "objects.png").string());
        int n = 0;
        for (std::uint16_t l : objects.labels) n = std::max(n, int(l));
        ASSERT_GT(n, 0) << stem;
        for (int id = n; id >= 1; --id) {
            std::vector<std::uint8_t> mask(objects.labels.size());
            for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = objects.labels[p] == id ? 255 : 0;
            char name[32];
            std::snprintf(name, sizeof name, "%s_%06d.png", stem, n - id);
            wul3d::write_mask_png((scene / "mask_visib" / name).string(), objects.width,
                                  objects.height, mask);
        }
    }
    const auto eval = run_cli({"eval", out.string(), scene.string()});
    ASSERT_EQ(eval.exit_code, 0) << wul3d::test::describe(eval);
    EXPECT_NE(eval.out.find("Overlap F   100.0"), std::string::npos) << eval.out;
    EXPECT_NE(eval.out.find("images      2"), std::string::npos) << eval.out;

    // One mask blanked: no longer perfect.
    const std::string first = std::string(kStems[0]) + "_000000.png";
    const wul3d::LabelImage m = wul3d::read_label_png((scene / "mask_visib" / first).string());
    wul3d::write_mask_png((scene / "mask_visib" / first).string(), m.width, m.height,
                          std::vector<std::uint8_t>(m.labels.size(), 0));
    const auto worse = run_cli({"eval", out.string(), scene.string()});
    ASSERT_EQ(worse.exit_code, 0) << wul3d::test::describe(worse);
    EXPECT_EQ(worse.out.find("Overlap F   100.0"), std::string::npos) << worse.out;
}

TEST(Bop, ASplitOrDatasetFolderAsksForOneScene) {
    TempDir tmp;
    make_scene(tmp.path());
    const std::string out = (tmp / "out").string();
    expect_one_line(run_cli({"run", (tmp / "test").string(), "--out", out}), 2,
                    {"BOP scenes", "000048", "wul3d.batch"});
    expect_one_line(run_cli({"run", tmp.path().string(), "--out", out}), 2, {"BOP scenes", "000048"});
    expect_one_line(run_cli({"run", (tmp / "test").string(), "--format", "bop", "--out", out}), 2,
                    {"BOP scenes", "000048"});
}

/// scene_camera.json with image `id`'s entry replaced by `cam` (or removed when null).
void set_camera(const fs::path& scene, int id, const nlohmann::json& cam) {
    nlohmann::json j = nlohmann::json::parse(wul3d::test::slurp(scene / "scene_camera.json"));
    if (cam.is_null())
        j.erase(std::to_string(id));
    else
        j[std::to_string(id)] = cam;
    wul3d::test::write_text(scene / "scene_camera.json", j.dump());
}

TEST(Bop, BadScenesAreOneLine) {
    TempDir tmp;
    const fs::path scene = make_scene(tmp.path());
    const std::string out = (tmp / "out").string();
    auto run = [&] { return run_cli({"run", scene.string(), "--out", out}); };
    const std::string good = wul3d::test::slurp(scene / "scene_camera.json");
    const nlohmann::json cam = cam_json(camera(1), 1.0);

    set_camera(scene, 3, nullptr);
    expect_one_line(run(), 2, {"scene_camera.json", "no image id 3", "000003.png"});
    nlohmann::json bad = cam;
    bad["cam_K"].erase(8);
    set_camera(scene, 3, bad);
    expect_one_line(run(), 2, {"image 3", "cam_K must be 9 finite numbers"});
    bad = cam;
    bad["cam_K"][2] = "320";
    set_camera(scene, 3, bad);
    expect_one_line(run(), 2, {"image 3", "cam_K must be 9 finite numbers"});
    bad = cam;
    bad["cam_K"][0] = nullptr;  // what a NaN becomes in JSON
    set_camera(scene, 3, bad);
    expect_one_line(run(), 2, {"image 3", "cam_K must be 9 finite numbers"});
    for (double s : {0.0, -1.0}) {
        bad = cam;
        bad["depth_scale"] = s;
        set_camera(scene, 3, bad);
        expect_one_line(run(), 2, {"image 3", "depth_scale", "millimetres per unit"});
    }
    bad = cam;
    bad.erase("depth_scale");
    set_camera(scene, 3, bad);
    expect_one_line(run(), 2, {"image 3", "no depth_scale"});
    wul3d::test::write_text(scene / "scene_camera.json", "{\"0\": ");
    expect_one_line(run(), 2, {"scene_camera.json", "invalid JSON"});
    fs::remove(scene / "scene_camera.json");
    expect_one_line(run(), 2, {"without scene_camera.json"});
    wul3d::test::write_text(scene / "scene_camera.json", good);

    // Colour against depth: another size, a missing image, an image without depth.
    wul3d::ColorImage small;
    small.width = 320;
    small.height = 240;
    small.rgb.assign(320 * 240 * 3, 90);
    const fs::path rgb3 = scene / "rgb" / "000003.png";
    fs::rename(rgb3, scene / "rgb.png");
    wul3d::write_color_png(rgb3.string(), small);
    expect_one_line(run(), 2, {"000003.png", "320x240", "640x480"});
    fs::remove(rgb3);
    expect_one_line(run(), 2, {"depth/000003.png has no rgb/000003"});
    fs::rename(scene / "rgb.png", scene / "rgb" / "000004.png");
    expect_one_line(run(), 2, {"depth/000003.png has no rgb/000003"});
    fs::rename(scene / "rgb" / "000004.png", rgb3);
    fs::copy_file(rgb3, scene / "rgb" / "000009.png");
    expect_one_line(run(), 2, {"rgb/000009.png has no depth/000009.png"});
    fs::remove(scene / "rgb" / "000009.png");

    ASSERT_EQ(run().exit_code, 0);  // restored: the checks above saw one fault each
    expect_one_line(run_cli({"eval", out, scene.string()}), 2, {"mask_visib", "no masks"});
    fs::remove_all(scene / "mask_visib");
    expect_one_line(run_cli({"eval", out, scene.string()}), 2, {"without mask_visib/"});
}

}  // namespace
