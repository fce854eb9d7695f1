// ozz-animation on one BVH clip: runtime bytes, error, and the time to sample
// a pose forward at 60 fps, as a game plays it.
//
//   ozz_bench [options] FILE.bvh
//     --end-sites      also make the BVH End Sites joints (default: the 31 joints tcb animates)
//     --cm-per-unit C  centimetres per BVH unit, for the tolerance and the errors (default 6.627)
//     --tolerance-cm T --distance-cm D
//                      the optimizer's setting (default 0.1 and 10: ozz's 1 mm at 10 cm)
//     --rounds R       timing rounds (default 51), --slice-ms MS per round and subject (default 20)
//     --json OUT       write the results as JSON
//
// The BVH reader is the one of ../shared/peers/acl/acl_bench.cpp (HIERARCHY
// with OFFSET / CHANNELS / End Site, then MOTION): a joint's local rotation is
// the product of its Euler channels in the order listed (degrees), its local
// translation its OFFSET (the root: OFFSET + its position channels).
//
// Why the BVH and not ozz's gltf2ozz on a file `tcb export` writes: gltf2ozz
// is part of ozz's import2ozz tool (jsoncpp from extern/, tiny_gltf, its own
// config and archive writers), more to build without cmake than this file;
// and reading the BVH gives ozz the same local transforms as
// ../shared/peers/acl, so the peers differ only in what they do with them.
// (ozz keeps key times as f32 either way, as glTF does.)
//
// Into ozz (0.16): a RawSkeleton of the joints (rest pose: the OFFSET, no
// rotation) and a RawAnimation in BVH units, its keys at the BVH's frame times:
// a rotation key per joint per frame, a translation key per frame for the
// root (the joints with position channels), one translation key (the OFFSET)
// for the others, no scale key (identity). Two runtime animations:
//   built      AnimationBuilder on the RawAnimation (every key; ozz stores
//              translations as half floats and rotations as 3 x 15 bits)
//   optimized  AnimationOptimizer first, by default with ozz's default setting
//              (1 mm tolerance measured 10 cm from each joint), converted to
//              BVH units: tolerance 0.1 / C, distance 10 / C (C = cm per unit)
//
// Bytes: Animation::size() (the runtime object and its buffers).
// Error: the ACL shell metric as ../shared/peers/acl measures it: at every
// BVH frame, the model-space distance (double FK) between points 3 cm along
// x, y and z of every joint, from the raw local transforms and from
// SamplingJob's output at that frame's time; max over joints and frames.
//
// Timing: forward = one SamplingJob::Context per subject, SamplingJob at
// ratio (i/60 s) / duration for i = 0..floor(60 d), the whole pose each time;
// "+ l2m" adds a LocalToModelJob of the pose. Each subject is warmed,
// calibrated to a slice, then timed in `rounds` round-robin rounds of whole
// passes; the median round is reported (wall clock), with the fastest round
// and the median round in thread CPU time (as acl_bench).

#include "ozz/animation/offline/animation_builder.h"
#include "ozz/animation/offline/animation_optimizer.h"
#include "ozz/animation/offline/raw_animation.h"
#include "ozz/animation/offline/raw_skeleton.h"
#include "ozz/animation/offline/skeleton_builder.h"
#include "ozz/animation/runtime/animation.h"
#include "ozz/animation/runtime/local_to_model_job.h"
#include "ozz/animation/runtime/sampling_job.h"
#include "ozz/animation/runtime/skeleton.h"
#include "ozz/base/maths/simd_math.h"
#include "ozz/base/maths/soa_transform.h"
#include "ozz/base/span.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
namespace oa = ozz::animation;
namespace oo = ozz::animation::offline;

// ---------------------------------------------------------------- BVH -----

struct Joint {
  std::string name;
  int parent = -1;
  double offset[3] = {0, 0, 0};
  std::vector<std::string> channels;  // empty for End Sites
  int first_channel = 0;              // index into a MOTION line
  bool end_site = false;
};

struct Bvh {
  std::vector<Joint> joints;  // depth-first order, parents first
  int num_channels = 0;
  int num_frames = 0;
  double frame_time = 0;
  std::vector<double> motion;  // num_frames * num_channels
};

bool ParseBvh(const char* path, Bvh& bvh) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "ozz_bench: cannot open %s\n", path);
    return false;
  }
  std::string tok;
  std::vector<int> stack;
  auto fail = [&](const char* what) {
    std::fprintf(stderr, "ozz_bench: BVH parse error near '%s': %s\n", tok.c_str(), what);
    return false;
  };
  in >> tok;
  if (tok != "HIERARCHY") return fail("expected HIERARCHY");
  int pending = -1;  // joint just declared, waiting for '{'
  while (in >> tok) {
    if (tok == "ROOT" || tok == "JOINT") {
      Joint j;
      in >> j.name;
      j.parent = stack.empty() ? -1 : stack.back();
      bvh.joints.push_back(j);
      pending = static_cast<int>(bvh.joints.size()) - 1;
    } else if (tok == "End") {
      std::string site;
      in >> site;  // "Site"
      if (stack.empty()) return fail("End Site outside a joint");
      Joint j;
      j.name = bvh.joints[stack.back()].name + "_End";
      j.parent = stack.back();
      j.end_site = true;
      bvh.joints.push_back(j);
      pending = static_cast<int>(bvh.joints.size()) - 1;
    } else if (tok == "{") {
      if (pending < 0) return fail("unexpected {");
      stack.push_back(pending);
      pending = -1;
    } else if (tok == "}") {
      if (stack.empty()) return fail("unbalanced }");
      stack.pop_back();
    } else if (tok == "OFFSET") {
      if (stack.empty()) return fail("OFFSET outside a joint");
      Joint& j = bvh.joints[stack.back()];
      in >> j.offset[0] >> j.offset[1] >> j.offset[2];
    } else if (tok == "CHANNELS") {
      if (stack.empty()) return fail("CHANNELS outside a joint");
      Joint& j = bvh.joints[stack.back()];
      int n = 0;
      in >> n;
      j.first_channel = bvh.num_channels;
      for (int i = 0; i < n; ++i) {
        std::string c;
        in >> c;
        j.channels.push_back(c);
      }
      bvh.num_channels += n;
    } else if (tok == "MOTION") {
      break;
    } else {
      return fail("unknown token in HIERARCHY");
    }
  }
  if (!stack.empty()) return fail("unbalanced braces");
  in >> tok;
  if (tok != "Frames:") return fail("expected Frames:");
  in >> bvh.num_frames;
  in >> tok;
  std::string tok2;
  in >> tok2;
  if (tok != "Frame" || tok2 != "Time:") return fail("expected Frame Time:");
  in >> bvh.frame_time;
  bvh.motion.resize(static_cast<size_t>(bvh.num_frames) * bvh.num_channels);
  for (double& v : bvh.motion) {
    if (!(in >> v)) return fail("short MOTION data");
  }
  double extra;
  if (in >> extra) return fail("trailing MOTION data");
  return true;
}

// ------------------------------------------------------- double math -----

struct Quat { double x, y, z, w; };
struct Vec3 { double x, y, z; };

Quat QMul(const Quat& a, const Quat& b) {  // Hamilton product a*b (b applied first)
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
          a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}
Vec3 QRot(const Quat& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t{2 * (u.y * v.z - u.z * v.y), 2 * (u.z * v.x - u.x * v.z), 2 * (u.x * v.y - u.y * v.x)};
  return {v.x + q.w * t.x + (u.y * t.z - u.z * t.y), v.y + q.w * t.y + (u.z * t.x - u.x * t.z),
          v.z + q.w * t.z + (u.x * t.y - u.y * t.x)};
}
Quat QAxis(int axis, double deg) {
  const double h = deg * (M_PI / 180.0) * 0.5;
  Quat q{0, 0, 0, std::cos(h)};
  (axis == 0 ? q.x : axis == 1 ? q.y : q.z) = std::sin(h);
  return q;
}
double Dist(const Vec3& a, const Vec3& b) {
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

struct Local { Quat r; Vec3 t; };

// Local transform of joint j at a BVH frame (translations in BVH units),
// its rotation normalized.
Local JointLocal(const Bvh& bvh, const Joint& j, int frame) {
  Local l{{0, 0, 0, 1}, {j.offset[0], j.offset[1], j.offset[2]}};
  const double* ch = &bvh.motion[static_cast<size_t>(frame) * bvh.num_channels + j.first_channel];
  for (size_t c = 0; c < j.channels.size(); ++c) {
    const std::string& n = j.channels[c];
    const int axis = n[0] == 'X' || n[0] == 'x' ? 0 : n[0] == 'Y' || n[0] == 'y' ? 1 : 2;
    if (n.find("rotation") != std::string::npos) {
      l.r = QMul(l.r, QAxis(axis, ch[c]));  // listed order, left to right
    } else {
      (axis == 0 ? l.t.x : axis == 1 ? l.t.y : l.t.z) += ch[c];
    }
  }
  const double n = std::sqrt(l.r.x * l.r.x + l.r.y * l.r.y + l.r.z * l.r.z + l.r.w * l.r.w);
  l.r = {l.r.x / n, l.r.y / n, l.r.z / n, l.r.w / n};
  return l;
}

bool HasPosition(const Joint& j) {
  for (const std::string& c : j.channels)
    if (c.find("position") != std::string::npos) return true;
  return false;
}

void Fk(const std::vector<int>& parents, const std::vector<Local>& local, std::vector<Local>& obj) {
  obj.resize(local.size());
  for (size_t i = 0; i < local.size(); ++i) {
    const int p = parents[i];
    if (p < 0) {
      obj[i] = local[i];
    } else {
      const Vec3 t = QRot(obj[p].r, local[i].t);
      obj[i].t = {obj[p].t.x + t.x, obj[p].t.y + t.y, obj[p].t.z + t.z};
      obj[i].r = QMul(obj[p].r, local[i].r);
    }
  }
}

// ----------------------------------------------------------- helpers -----

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

volatile float g_sink;

// Joint i of a SoA pose as doubles.
Local FromSoa(const ozz::vector<ozz::math::SoaTransform>& pose, int i) {
  const ozz::math::SoaTransform& s = pose[i / 4];
  const int l = i % 4;
  float v[4];
  auto lane = [&](ozz::math::SimdFloat4 x) {
    ozz::math::StorePtrU(x, v);
    return double(v[l]);
  };
  return {{lane(s.rotation.x), lane(s.rotation.y), lane(s.rotation.z), lane(s.rotation.w)},
          {lane(s.translation.x), lane(s.translation.y), lane(s.translation.z)}};
}

// Appends joint `j` of the BVH (kept joints only) and its subtree to `out`.
void AddJoint(const Bvh& bvh, const std::vector<bool>& kept, int j, oo::RawSkeleton::Joint::Children& out) {
  out.emplace_back();
  oo::RawSkeleton::Joint& rj = out.back();
  const Joint& b = bvh.joints[j];
  rj.name = b.name.c_str();
  rj.transform = ozz::math::Transform::identity();
  rj.transform.translation =
      ozz::math::Float3(float(b.offset[0]), float(b.offset[1]), float(b.offset[2]));
  for (size_t c = 0; c < bvh.joints.size(); ++c)
    if (kept[c] && bvh.joints[c].parent == j) AddJoint(bvh, kept, int(c), rj.children);
}

struct Result {
  const char* name;
  size_t bytes = 0;
  size_t keys[3] = {0, 0, 0};  // translation, rotation, scale keys in the RawAnimation built from
  double max_err = 0;           // BVH units
  int max_joint = 0, max_frame = 0;
  double fwd_ns[2] = {0, 0}, fwd_min[2] = {0, 0}, fwd_max[2] = {0, 0}, fwd_cpu[2] = {0, 0};  // per pose: sample, sample + l2m
};

}  // namespace

int main(int argc, char** argv) {
  bool end_sites = false;
  double cm_per_unit = 6.627, tolerance_cm = 0.1, distance_cm = 10;
  int rounds = 51;
  double slice_ms = 20;
  const char* json_path = nullptr;
  const char* bvh_path = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "ozz_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--end-sites") end_sites = true;
    else if (a == "--cm-per-unit") cm_per_unit = std::atof(next());
    else if (a == "--tolerance-cm") tolerance_cm = std::atof(next());
    else if (a == "--distance-cm") distance_cm = std::atof(next());
    else if (a == "--rounds") rounds = std::atoi(next());
    else if (a == "--slice-ms") slice_ms = std::atof(next());
    else if (a == "--json") json_path = next();
    else if (a[0] != '-' && !bvh_path) bvh_path = argv[i];
    else {
      std::fprintf(stderr, "ozz_bench: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (!bvh_path || rounds < 1 || slice_ms <= 0 || cm_per_unit <= 0 || !(tolerance_cm > 0) || !(distance_cm > 0)) {
    std::fprintf(stderr, "usage: ozz_bench [--end-sites] [--cm-per-unit C] [--tolerance-cm T] [--distance-cm D] "
                         "[--rounds R] [--slice-ms MS] "
                         "[--json OUT] FILE.bvh\n");
    return 2;
  }

  Bvh bvh;
  if (!ParseBvh(bvh_path, bvh)) return 1;
  if (bvh.num_frames < 2) {
    std::fprintf(stderr, "ozz_bench: need at least 2 frames\n");
    return 1;
  }
  std::vector<bool> kept(bvh.joints.size());
  int num_animated = 0;
  for (size_t i = 0; i < bvh.joints.size(); ++i) {
    kept[i] = end_sites || !bvh.joints[i].end_site;
    num_animated += !bvh.joints[i].end_site;
  }

  // ------------------------------------------------------------ skeleton --
  oo::RawSkeleton raw_skeleton;
  for (size_t i = 0; i < bvh.joints.size(); ++i)
    if (kept[i] && bvh.joints[i].parent < 0) AddJoint(bvh, kept, int(i), raw_skeleton.roots);
  if (!raw_skeleton.Validate()) {
    std::fprintf(stderr, "ozz_bench: RawSkeleton invalid\n");
    return 1;
  }
  ozz::unique_ptr<oa::Skeleton> skeleton = oo::SkeletonBuilder()(raw_skeleton);
  if (!skeleton) {
    std::fprintf(stderr, "ozz_bench: SkeletonBuilder failed\n");
    return 1;
  }
  const int nj = skeleton->num_joints();
  // ozz joint -> BVH joint, by name; parents in ozz order.
  std::vector<int> bvh_of(nj, -1), parents(nj);
  for (int i = 0; i < nj; ++i) {
    for (size_t b = 0; b < bvh.joints.size(); ++b)
      if (kept[b] && bvh.joints[b].name == skeleton->joint_names()[i]) bvh_of[i] = int(b);
    if (bvh_of[i] < 0) {
      std::fprintf(stderr, "ozz_bench: joint %s not found\n", skeleton->joint_names()[i]);
      return 1;
    }
    parents[i] = skeleton->joint_parents()[i];
  }

  // ----------------------------------------------------------- animation --
  const int nf = bvh.num_frames;
  const double dt = bvh.frame_time;
  oo::RawAnimation raw;
  raw.duration = float((nf - 1) * dt);
  raw.name = "cmu";
  raw.tracks.resize(nj);
  std::vector<Local> ref(size_t(nf) * nj);  // raw locals, frame-major
  for (int f = 0; f < nf; ++f)
    for (int i = 0; i < nj; ++i) ref[size_t(f) * nj + i] = JointLocal(bvh, bvh.joints[bvh_of[i]], f);
  for (int i = 0; i < nj; ++i) {
    const Joint& b = bvh.joints[bvh_of[i]];
    oo::RawAnimation::JointTrack& track = raw.tracks[i];
    const bool moves = HasPosition(b), turns = !b.channels.empty();
    for (int f = 0; f < (moves ? nf : 1); ++f) {
      const Local& l = ref[size_t(f) * nj + i];
      track.translations.push_back({float(f * dt), ozz::math::Float3(float(l.t.x), float(l.t.y), float(l.t.z))});
    }
    for (int f = 0; f < (turns ? nf : 1); ++f) {
      const Local& l = ref[size_t(f) * nj + i];
      track.rotations.push_back(
          {float(f * dt), ozz::math::Quaternion(float(l.r.x), float(l.r.y), float(l.r.z), float(l.r.w))});
    }
  }
  if (!raw.Validate()) {
    std::fprintf(stderr, "ozz_bench: RawAnimation invalid\n");
    return 1;
  }

  oo::AnimationOptimizer optimizer;
  optimizer.setting.tolerance = float(tolerance_cm / cm_per_unit);
  optimizer.setting.distance = float(distance_cm / cm_per_unit);
  oo::RawAnimation raw_opt;
  const auto o0 = Clock::now();
  if (!optimizer(raw, *skeleton, &raw_opt)) {
    std::fprintf(stderr, "ozz_bench: AnimationOptimizer failed\n");
    return 1;
  }
  const double optimize_s = std::chrono::duration<double>(Clock::now() - o0).count();

  oo::AnimationBuilder builder;
  ozz::unique_ptr<oa::Animation> anims[2] = {builder(raw), builder(raw_opt)};
  const oo::RawAnimation* raws[2] = {&raw, &raw_opt};
  if (!anims[0] || !anims[1]) {
    std::fprintf(stderr, "ozz_bench: AnimationBuilder failed\n");
    return 1;
  }
  Result res[2];
  res[0].name = "built";
  res[1].name = "optimized";
  const float duration = anims[0]->duration();
  std::printf("clip %s: %zu joints (%d with channels), %d frames, frame time %.7g s; ozz skeleton %d joints, "
              "duration %.4f s\n",
              bvh_path, bvh.joints.size(), num_animated, nf, dt, nj, duration);
  std::printf("optimizer: tolerance %.6g units (%g cm at %.4g cm per unit), distance %.6g units (%g cm), %.3f s\n",
              optimizer.setting.tolerance, tolerance_cm, cm_per_unit, optimizer.setting.distance, distance_cm,
              optimize_s);

  // --------------------------------------------------------------- error --
  ozz::vector<ozz::math::SoaTransform> pose(skeleton->num_soa_joints());
  ozz::vector<ozz::math::Float4x4> models(nj);
  const double shell = 3.0 / cm_per_unit;
  const Vec3 pts[3] = {{shell, 0, 0}, {0, shell, 0}, {0, 0, shell}};
  for (int k = 0; k < 2; ++k) {
    Result& r = res[k];
    r.bytes = anims[k]->size();
    for (const oo::RawAnimation::JointTrack& t : raws[k]->tracks)
      r.keys[0] += t.translations.size(), r.keys[1] += t.rotations.size(), r.keys[2] += t.scales.size();
    oa::SamplingJob::Context ctx(nj);
    oa::SamplingJob job;
    job.animation = anims[k].get();
    job.context = &ctx;
    job.output = ozz::make_span(pose);
    std::vector<Local> lraw(nj), ldec(nj), oraw, odec;
    r.max_err = -1;
    for (int f = 0; f < nf; ++f) {
      job.ratio = float(f * dt / duration);
      if (!job.Run()) {
        std::fprintf(stderr, "ozz_bench: SamplingJob failed\n");
        return 1;
      }
      for (int i = 0; i < nj; ++i) lraw[i] = ref[size_t(f) * nj + i], ldec[i] = FromSoa(pose, i);
      Fk(parents, lraw, oraw);
      Fk(parents, ldec, odec);
      for (int i = 0; i < nj; ++i) {
        for (const Vec3& p : pts) {
          const Vec3 a = QRot(oraw[i].r, p), c = QRot(odec[i].r, p);
          const double e = Dist({a.x + oraw[i].t.x, a.y + oraw[i].t.y, a.z + oraw[i].t.z},
                                {c.x + odec[i].t.x, c.y + odec[i].t.y, c.z + odec[i].t.z});
          if (e > r.max_err) r.max_err = e, r.max_joint = i, r.max_frame = f;
        }
      }
    }
    std::printf("%-9s %9zu bytes (Animation::size()); raw keys T %zu R %zu S %zu; max error %.4e units = %.5f cm "
                "(3 cm shell) at %s frame %d\n",
                r.name, r.bytes, r.keys[0], r.keys[1], r.keys[2], r.max_err, r.max_err * cm_per_unit,
                skeleton->joint_names()[r.max_joint], r.max_frame);
  }

  // -------------------------------------------------------------- timing --
  const size_t nt = static_cast<size_t>(std::floor(double(duration) * 60.0 + 1e-9));
  std::vector<float> ratios(nt + 1);
  for (size_t i = 0; i <= nt; ++i) ratios[i] = std::min(1.f, float(double(i) / 60.0 / duration));

  struct Subject {
    int anim;
    bool l2m;
    uint64_t iters = 1;
    std::vector<double> seconds, cpu_seconds;
    oa::SamplingJob::Context* ctx = nullptr;
  };
  std::vector<std::unique_ptr<oa::SamplingJob::Context>> contexts;
  Subject subjects[4] = {{0, false}, {0, true}, {1, false}, {1, true}};
  for (Subject& s : subjects) {  // one context each, as one character per clip
    contexts.emplace_back(new oa::SamplingJob::Context(nj));
    s.ctx = contexts.back().get();
  }
  oa::LocalToModelJob l2m;
  l2m.skeleton = skeleton.get();
  l2m.input = ozz::make_span(pose);
  l2m.output = ozz::make_span(models);
  auto pass = [&](Subject& s) {
    oa::SamplingJob job;
    job.animation = anims[s.anim].get();
    job.context = s.ctx;
    job.output = ozz::make_span(pose);
    for (float r : ratios) {
      job.ratio = r;
      job.Run();
      if (s.l2m) l2m.Run();
    }
    float v[4];
    ozz::math::StorePtrU(pose[0].rotation.x, v);
    g_sink = v[0];
  };
  const double slice = slice_ms * 1e-3;
  for (Subject& s : subjects) {
    pass(s);
    const auto t0 = Clock::now();
    uint64_t k = 0;
    double el = 0;
    do {
      pass(s);
      ++k;
      el = std::chrono::duration<double>(Clock::now() - t0).count();
    } while (el < slice / 4);
    s.iters = std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(slice / (el / k))));
  }
  for (int r = 0; r < rounds; ++r) {
    for (Subject& s : subjects) {
      const double c0 = ThreadCpuSeconds();
      const auto t0 = Clock::now();
      for (uint64_t i = 0; i < s.iters; ++i) pass(s);
      s.seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / s.iters);
      s.cpu_seconds.push_back((ThreadCpuSeconds() - c0) / s.iters);
    }
  }
  for (const Subject& s : subjects) {
    std::vector<double> pp, cp;
    for (double sec : s.seconds) pp.push_back(sec * 1e9 / ratios.size());
    for (double sec : s.cpu_seconds) cp.push_back(sec * 1e9 / ratios.size());
    Result& r = res[s.anim];
    const int c = s.l2m;
    r.fwd_ns[c] = Median(pp);
    r.fwd_cpu[c] = Median(cp);
    r.fwd_min[c] = *std::min_element(pp.begin(), pp.end());
    r.fwd_max[c] = *std::max_element(pp.begin(), pp.end());
    std::printf("timing %-9s %-14s %5zu poses/pass, %llu passes/round, %d rounds: %.1f ns/pose (min %.1f max %.1f; "
                "thread CPU time %.1f) = %.3f ns per joint (%d joints)\n",
                r.name, c ? "sample + l2m" : "sample", ratios.size(), static_cast<unsigned long long>(s.iters), rounds,
                r.fwd_ns[c], r.fwd_min[c], r.fwd_max[c], r.fwd_cpu[c], r.fwd_ns[c] / nj, nj);
  }

  if (json_path) {
    FILE* f = std::fopen(json_path, "w");
    if (!f) {
      std::fprintf(stderr, "ozz_bench: cannot write %s\n", json_path);
      return 1;
    }
    std::fprintf(f, "{\"joints\": %d, \"end_sites\": %s, \"frames\": %d, \"duration_s\": %.6f, \"cm_per_unit\": %g, "
                    "\"tolerance_cm\": %g, \"distance_cm\": %g, \"tolerance_units\": %.7g, \"distance_units\": %.7g, \"poses\": %zu, \"rounds\": %d, "
                    "\"slice_ms\": %g, \"animations\": {",
                 nj, end_sites ? "true" : "false", nf, double(duration), cm_per_unit, tolerance_cm, distance_cm,
                 optimizer.setting.tolerance,
                 optimizer.setting.distance, ratios.size(), rounds, slice_ms);
    for (int k = 0; k < 2; ++k) {
      const Result& r = res[k];
      std::fprintf(f, "%s\"%s\": {\"bytes\": %zu, \"keys_t\": %zu, \"keys_r\": %zu, \"keys_s\": %zu, "
                      "\"max_error_units\": %.6g, \"max_error_cm\": %.6g, \"max_error_joint\": \"%s\", "
                      "\"max_error_frame\": %d, \"sample_ns\": %.3f, \"sample_ns_min\": %.3f, \"sample_ns_max\": %.3f, "
                      "\"sample_cpu_ns\": %.3f, \"l2m_ns\": %.3f, \"l2m_ns_min\": %.3f, \"l2m_ns_max\": %.3f, "
                      "\"l2m_cpu_ns\": %.3f}",
                   k ? ", " : "", r.name, r.bytes, r.keys[0], r.keys[1], r.keys[2], r.max_err, r.max_err * cm_per_unit,
                   skeleton->joint_names()[r.max_joint], r.max_frame, r.fwd_ns[0], r.fwd_min[0], r.fwd_max[0],
                   r.fwd_cpu[0], r.fwd_ns[1], r.fwd_min[1], r.fwd_max[1], r.fwd_cpu[1]);
    }
    std::fprintf(f, "}}\n");
    std::fclose(f);
  }
  return 0;
}
