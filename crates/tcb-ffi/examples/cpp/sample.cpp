// The tcb C API from C++: handles owned by std::unique_ptr, errors thrown
// as exceptions, rows in std::vector. Build (from the repository's root,
// after `cargo build --release -p tcb-ffi`):
//
//   c++ -std=c++17 -Wall -Wextra -I crates/tcb-ffi/include
//       crates/tcb-ffi/examples/cpp/sample.cpp -L target/release -ltcb_ffi
//       -Wl,-rpath,"$PWD/target/release" -o sample_cpp
//   ./sample_cpp data/cmu-01_01.bvh 1.5
//
// It prints `Hips.translation,<t>,<x>,<y>,<z>` as the C example does.
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "tcb.h"

namespace tcb {

// Throws the library's message when a call fails.
inline void check(TcbStatus status, const char *what) {
    if (status != TCB_STATUS_OK) {
        throw std::runtime_error(std::string(what) + ": " + tcb_last_error_message());
    }
}

struct ClipFree { void operator()(TcbClip *p) const { tcb_clip_free(p); } };
struct InstanceFree { void operator()(TcbInstance *p) const { tcb_instance_free(p); } };
struct SkeletonFree { void operator()(TcbSkeleton *p) const { tcb_skeleton_free(p); } };
using Clip = std::unique_ptr<TcbClip, ClipFree>;
using Instance = std::unique_ptr<TcbInstance, InstanceFree>;
using Skeleton = std::unique_ptr<TcbSkeleton, SkeletonFree>;

inline Clip load(const std::string &path) {
    TcbClip *clip = nullptr;
    check(tcb_clip_load_file(path.c_str(), 0, &clip), "tcb_clip_load_file");
    return Clip(clip);
}

inline Instance instance(const Clip &clip) {
    TcbInstance *inst = nullptr;
    check(tcb_instance_new(clip.get(), 0, &inst), "tcb_instance_new");
    return Instance(inst);
}

inline std::string track_name(const Clip &clip, size_t index) {
    size_t len = 0;
    tcb_clip_track_name(clip.get(), index, nullptr, 0, &len);  // the length
    std::string name(len + 1, '\0');
    check(tcb_clip_track_name(clip.get(), index, &name[0], name.size(), &len),
          "tcb_clip_track_name");
    name.resize(len);
    return name;
}

}  // namespace tcb

int main(int argc, char **argv) {
    const std::string path = argc > 1 ? argv[1] : "data/cmu-01_01.bvh";
    const double t = argc > 2 ? std::stod(argv[2]) : 1.5;
    try {
        tcb::Clip clip = tcb::load(path);
        tcb::Instance inst = tcb::instance(clip);
        std::vector<float> row(tcb_instance_channel_count(inst.get()));
        tcb::check(tcb_instance_sample(inst.get(), t, row.data(), row.size()),
                   "tcb_instance_sample");

        TcbTrackInfo hips{};
        tcb::check(tcb_clip_find_track(clip.get(), "Hips.translation", &hips), "find");
        const float *p = &row[hips.offset];
        std::printf("Hips.translation,%.17g,%.9g,%.9g,%.9g\n", t, p[0], p[1], p[2]);
        std::printf("first track: %s, last track: %s\n", tcb::track_name(clip, 0).c_str(),
                    tcb::track_name(clip, tcb_clip_track_count(clip.get()) - 1).c_str());

        TcbSkeleton *raw = nullptr;
        tcb::check(tcb_skeleton_new(clip.get(), clip.get(), &raw), "tcb_skeleton_new");
        tcb::Skeleton skeleton(raw);
        std::vector<float> matrices(tcb_skeleton_joint_count(skeleton.get()) * TCB_MATRIX_FLOATS);
        tcb::check(tcb_skeleton_model_matrices(skeleton.get(), inst.get(), matrices.data(),
                                               matrices.size()),
                   "tcb_skeleton_model_matrices");
        size_t head = 0;
        tcb::check(tcb_skeleton_find_joint(skeleton.get(), "Head", &head), "find joint");
        const float *m = &matrices[head * TCB_MATRIX_FLOATS];
        std::printf("Head model-space position at %.2f s, in the file's units: %.4f %.4f %.4f\n", t,
                    m[12], m[13], m[14]);

        // An error is an exception here, with the library's message.
        try {
            tcb::load("no/such/file.bvh");
        } catch (const std::exception &e) {
            std::printf("expected error: %s\n", e.what());
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
