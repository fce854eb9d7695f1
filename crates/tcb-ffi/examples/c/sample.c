/* The tcb C API from C: load a BVH file, sample it, read a track and a
 * joint's model-space matrix, cross-fade two instances through a rig, and
 * show an error. Build (from the repository's root, after
 * `cargo build --release -p tcb-ffi`):
 *
 *   cc -std=c11 -Wall -Wextra -I crates/tcb-ffi/include \
 *      crates/tcb-ffi/examples/c/sample.c target/release/libtcb_ffi.a \
 *      -lpthread -ldl -lm -o sample
 *   ./sample data/cmu-01_01.bvh 1.5
 *
 * It prints `Hips.translation,<t>,<x>,<y>,<z>`, the values
 * `tcb sample FILE --at <t>` prints in its Hips.translation columns
 * (.ci/run compares them). */
#include <stdio.h>
#include <stdlib.h>

#include "tcb.h"

/* Print the last error and fail. */
#define CHECK(call)                                                        \
    do {                                                                   \
        TcbStatus status_ = (call);                                        \
        if (status_ != TCB_STATUS_OK) {                                    \
            fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__,       \
                    __LINE__, #call, (int)status_, tcb_last_error_message()); \
            exit(1);                                                       \
        }                                                                  \
    } while (0)

int main(int argc, char **argv) {
    const char *path = argc > 1 ? argv[1] : "data/cmu-01_01.bvh";
    double t = argc > 2 ? atof(argv[2]) : 1.5;

    /* Load and compile once. */
    TcbClip *clip = NULL;
    CHECK(tcb_clip_load_file(path, 0, &clip));
    double start = 0.0, end = 0.0;
    CHECK(tcb_clip_time_range(clip, &start, &end));
    printf("tcb %s: %s, %zu tracks, %zu floats a row, keys from %.4f to %.4f s\n",
           tcb_version(), path, tcb_clip_track_count(clip),
           tcb_clip_channel_count(clip), start, end);

    /* One instance; a row of floats, sampled every frame (no allocation). */
    TcbInstance *inst = NULL;
    CHECK(tcb_instance_new(clip, 0, &inst));
    size_t n = tcb_instance_channel_count(inst);
    float *row = malloc(n * sizeof *row);
    if (!row) return 1;
    CHECK(tcb_instance_sample(inst, t, row, n));
    TcbTrackInfo hips;
    CHECK(tcb_clip_find_track(clip, "Hips.translation", &hips));
    const float *p = row + hips.offset;
    printf("Hips.translation,%.17g,%.9g,%.9g,%.9g\n", t, p[0], p[1], p[2]);

    /* Model-space matrices of the pose just sampled (16 floats a joint). */
    TcbSkeleton *skel = NULL;
    CHECK(tcb_skeleton_new(clip, clip, &skel));
    size_t joints = tcb_skeleton_joint_count(skel);
    float *matrices = malloc(joints * TCB_MATRIX_FLOATS * sizeof *matrices);
    if (!matrices) return 1;
    CHECK(tcb_skeleton_model_matrices(skel, inst, matrices, joints * TCB_MATRIX_FLOATS));
    size_t hand = 0;
    CHECK(tcb_skeleton_find_joint(skel, "LeftHand", &hand));
    const float *m = matrices + hand * TCB_MATRIX_FLOATS;
    printf("LeftHand model-space position at %.2f s, in the file's units: %.4f %.4f %.4f"
           " (of %zu joints)\n",
           t, m[12], m[13], m[14], joints);
    /* Or each joint's local translation, rotation, scale (10 floats a joint). */
    float *locals = malloc(joints * TCB_TRANSFORM_FLOATS * sizeof *locals);
    if (!locals) return 1;
    CHECK(tcb_skeleton_local_transforms(skel, inst, locals, joints * TCB_TRANSFORM_FLOATS));
    printf("Hips local rotation (quaternion x y z w): %.4f %.4f %.4f %.4f\n", locals[3],
           locals[4], locals[5], locals[6]);
    free(locals);

    /* Cross-fade two instances through a rig into a pose of the rig. */
    TcbRig *rig = NULL;
    CHECK(tcb_rig_from_skeleton(clip, &rig));
    TcbInstance *walk = NULL, *later = NULL;
    CHECK(tcb_instance_new_with_rig(clip, rig, 0, &walk));
    CHECK(tcb_instance_new_with_rig(clip, rig, 0, &later));
    CHECK(tcb_instance_set_playback(later, TCB_PLAYBACK_LOOP, 1.0));
    TcbPose *mixed = NULL;
    CHECK(tcb_pose_new_for_rig(rig, 0, &mixed));
    TcbSkeleton *rig_skel = NULL;
    CHECK(tcb_skeleton_new_for_rig(clip, rig, &rig_skel));
    for (int frame = 0; frame < 60; frame++) {
        double now = t + frame / 60.0;
        CHECK(tcb_instance_update(walk, now));
        CHECK(tcb_instance_update(later, now + 10.0));
        const TcbInstance *layers[2] = {walk, later};
        float w = (float)frame / 59.0f;
        float weights[2] = {1.0f - w, w};
        CHECK(tcb_blend(mixed, layers, weights, 2));
        CHECK(tcb_skeleton_model_matrices_pose(rig_skel, mixed, matrices,
                                               joints * TCB_MATRIX_FLOATS));
    }
    printf("LeftHand after the cross-fade, in the file's units: %.4f %.4f %.4f\n", m[12], m[13],
           m[14]);

    /* Errors: a status and a message, never a crash. */
    TcbClip *missing = NULL;
    TcbStatus status = tcb_clip_load_file("no/such/file.bvh", 0, &missing);
    printf("loading a missing file: status %d, clip %s, \"%s\"\n", (int)status,
           missing ? "set" : "NULL", tcb_last_error_message());
    status = tcb_instance_sample(inst, t, row, n - 1);
    printf("a short row: status %d, \"%s\"\n", (int)status, tcb_last_error_message());

    free(matrices);
    free(row);
    tcb_skeleton_free(rig_skel);
    tcb_pose_free(mixed);
    tcb_instance_free(later);
    tcb_instance_free(walk);
    tcb_rig_free(rig);
    tcb_skeleton_free(skel);
    tcb_instance_free(inst);
    tcb_clip_free(clip);
    return 0;
}
