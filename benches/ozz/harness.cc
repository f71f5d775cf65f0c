// Times ozz-animation's own SkinningJob (positions only, then positions and normals) on the
// jobs Marionette writes
// (`MARIONETTE_OZZ_DUMP=smpl.bin MARIONETTE_DATA=../shared/data cargo bench --profile dev
// --bench marionette`), and checks its output against Marionette's plain-loop oracle.
// Built outside the project against ozz-animation's own sources:
//   g++ -O3 -mavx2 -mfma -DNDEBUG -I OZZ/include -I OZZ/src harness.cc \
//       OZZ/src/geometry/runtime/skinning_job.cc -o ozz_harness
//   ./ozz_harness smpl.bin
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>
#include "ozz/geometry/runtime/skinning_job.h"
#include "ozz/base/maths/simd_math.h"

struct Job { uint32_t k, n; std::vector<float> pos, out, nrm, nout; std::vector<uint16_t> idx; std::vector<float> w; };

int main(int argc, char** argv) {
  FILE* f = fopen(argv[1], "rb");
  auto u32 = [&]() { uint32_t v; fread(&v, 4, 1, f); return v; };
  uint32_t jobs_n = u32();
  std::vector<Job> jobs(jobs_n);
  for (auto& j : jobs) {
    j.k = u32(); j.n = u32();
    j.pos.resize(j.n * 3 + 1); fread(j.pos.data(), 4, j.n * 3, f);  // +1: ozz loads four floats
    j.idx.resize(j.n * j.k); fread(j.idx.data(), 2, j.n * j.k, f);
    j.w.resize(j.n * (j.k - 1) + 1); fread(j.w.data(), 4, j.n * (j.k - 1), f);
    j.out.resize(j.n * 3 + 1);
    // Normals for the timing with normals: unit vectors from the centre out (their values do
    // not change the work; Marionette's bench uses the same).
    double c[3] = {0, 0, 0};
    for (uint32_t v = 0; v < j.n; ++v) for (int a = 0; a < 3; ++a) c[a] += j.pos[v * 3 + a] / j.n;
    j.nrm.resize(j.n * 3 + 1); j.nout.resize(j.n * 3 + 1);
    for (uint32_t v = 0; v < j.n; ++v) {
      float d[3]; double l = 0;
      for (int a = 0; a < 3; ++a) { d[a] = j.pos[v * 3 + a] - float(c[a]); l += double(d[a]) * d[a]; }
      l = l > 0 ? 1 / std::sqrt(l) : 0;
      for (int a = 0; a < 3; ++a) j.nrm[v * 3 + a] = float(d[a] * l);
    }
  }
  uint32_t joints = u32();
  std::vector<ozz::math::Float4x4> palette(joints);
  for (auto& m : palette) { float c[16]; fread(c, 4, 16, f); for (int i = 0; i < 4; ++i) m.cols[i] = ozz::math::simd_float4::LoadPtrU(c + 4 * i); }
  size_t vertices = 0; for (auto& j : jobs) vertices += j.n;
  std::vector<std::vector<float>> want(jobs.size());
  for (size_t i = 0; i < jobs.size(); ++i) { want[i].resize(jobs[i].n * 3); fread(want[i].data(), 4, jobs[i].n * 3, f); }
  const int reps = argc > 2 ? atoi(argv[2]) : 2000;
  auto time = [&](bool normals) {
    double best = 1e30;
    for (int round = 0; round < 5; ++round) {
      auto t0 = std::chrono::steady_clock::now();
      for (int r = 0; r < reps; ++r) {
        for (auto& j : jobs) {
          ozz::geometry::SkinningJob job;
          job.vertex_count = j.n; job.influences_count = j.k;
          job.joint_matrices = ozz::make_span(palette);
          job.joint_indices = ozz::make_span(j.idx); job.joint_indices_stride = sizeof(uint16_t) * j.k;
          if (j.k > 1) { job.joint_weights = ozz::make_span(j.w); job.joint_weights_stride = sizeof(float) * (j.k - 1); }
          job.in_positions = ozz::make_span(j.pos); job.in_positions_stride = sizeof(float) * 3;
          job.out_positions = ozz::make_span(j.out); job.out_positions_stride = sizeof(float) * 3;
          if (normals) {
            job.in_normals = ozz::make_span(j.nrm); job.in_normals_stride = sizeof(float) * 3;
            job.out_normals = ozz::make_span(j.nout); job.out_normals_stride = sizeof(float) * 3;
          }
          if (!job.Run()) { fprintf(stderr, "invalid job\n"); exit(1); }
        }
      }
      double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / reps;
      if (s < best) best = s;
    }
    return best;
  };
  double best = time(false), with_normals = time(true);
  float worst = 0;
  for (size_t i = 0; i < jobs.size(); ++i) for (size_t v = 0; v < jobs[i].n * 3; ++v) { float d = jobs[i].out[v] - want[i][v]; if (d < 0) d = -d; if (d > worst) worst = d; }
  printf("largest difference from Marionette's plain-loop oracle: %g\n", worst);
  printf("ozz SkinningJob: %zu vertices in %.2f us, %.1f M vertices/s\n", vertices, best * 1e6, vertices / best / 1e6);
  printf("ozz SkinningJob with normals: %.2f us, %.1f M vertices/s\n", with_normals * 1e6, vertices / with_normals / 1e6);
  return 0;
}
