// Cost of an estimator's set-up per template: the 360 rotations (TemplateRotations), the exact
// search's cell tables made ahead (MakeTables, what hposed does at start; `hpose estimate`
// makes only those its frame reads), and the refinement's surface normals (SurfaceModel). Each
// is timed as thread CPU time over --repeat runs (median), and digested: the rotations' and theta
// blocks' columns (with the slabs'), the tables' words and the normals' bits, so that two
// builds can be shown to make the same.
//   taskset -c 0 setup_bench [--repeat N] [TEMPLATE.bt ...]   (default: the shipped templates)
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_frames.h"
#include "core/scoring/pose_lattice.h"
#include "core/search/surface_model.h"
#include "core/templates/template_io.h"

namespace hpose::bench {
namespace {

// FNV-1a over bytes, and the size of what went in.
struct Digest {
  std::uint64_t h = 1469598103934665603ULL;
  size_t bytes = 0;
  void Add(const void* p, size_t n) {
    const unsigned char* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ULL;
    bytes += n;
  }
  void Add(const CellGroups& g) {
    Add(g.words.data(), g.words.size() * sizeof(std::uint64_t));
    Add(&g.runs, sizeof(g.runs));
  }
};

template <typename T>
void AddVector(const std::vector<T>& v, Digest* d) {
  const size_t n = v.size();
  d->Add(&n, sizeof(n));
  d->Add(v.data(), n * sizeof(T));
}

void DigestRotated(const RotatedTemplate& r, Digest* d) {
  const int head[] = {r.itheta,    r.q_min.x(), r.q_min.y(), r.q_max.x(),
                      r.q_max.y(), r.z_base,    r.z_words};
  d->Add(head, sizeof(head));
  AddVector(r.sub_cells, d);
  AddVector(r.column_q, d);
  AddVector(r.column_masks, d);
  AddVector(r.column_extent, d);
  AddVector(r.column_cxe, d);
  AddVector(r.column_cy, d);
}

// What a TemplateRotations holds from its construction: every rotation and theta block with
// their free-space masks and extents (a template's slabs after it).
void DigestRotations(const TemplateRotations& rot, Digest* d) {
  std::vector<const TemplateRotations*> parts{&rot};
  for (const auto& slab : rot.slabs()) parts.push_back(slab.get());
  for (const TemplateRotations* part : parts) {
    const int steps = part->lattice().angle_steps;
    const int head[] = {part->max_block_extent(), part->column_q_min().x(),
                        part->column_q_min().y(), part->column_q_max().x(),
                        part->column_q_max().y(), part->z_words()};
    d->Add(head, sizeof(head));
    for (int i = 0; i < steps; ++i) {
      DigestRotated(part->Get(i), d);
      AddVector(part->DisjointMasks(i), d);
    }
    for (int t = 1; t < TemplateRotations::kThetaLevels; ++t) {
      const int extent = part->block_extent(t);
      d->Add(&extent, sizeof(extent));
      for (int first = 0; first < steps; first += 1 << t)
        DigestRotated(part->GetBlock(t, first), d);
    }
  }
}

// Every table MakeTables makes, in a fixed order (a template's slabs after it).
void DigestTables(const TemplateRotations& rot, Digest* d) {
  std::vector<const TemplateRotations*> parts{&rot};
  for (const auto& slab : rot.slabs()) parts.push_back(slab.get());
  for (const TemplateRotations* part : parts) {
    if (!part->has_cell_groups()) continue;
    const PoseLattice& lattice = part->lattice();
    const int s = lattice.subdivisions, steps = lattice.angle_steps;
    const auto residues = [&](int level, auto&& f) {
      const int step = level == 0 ? 1 : std::min(1 << level, s);
      for (int ra = 0; ra < s; ra += step) {
        for (int rb = 0; rb < s; rb += step) f(ra, rb);
      }
    };
    for (int i = 0; i < steps; ++i) {
      residues(0, [&](int ra, int rb) { d->Add(part->Groups(i, ra, rb)); });
      for (int ra = 0; ra < s; ra += 2) {
        for (int rb = 0; rb < s; rb += 2) {
          const PairBlockTable& t = part->PairTable(i, ra, rb);
          d->Add(t.cxe.data(), t.cxe.size() * sizeof(std::int32_t));
          d->Add(t.cy.data(), t.cy.size() * sizeof(std::int32_t));
        }
      }
      for (int level = 1; level <= TemplateRotations::kSweptLevels; ++level) {
        residues(level, [&](int ra, int rb) { d->Add(part->SweptGroups(i, level, ra, rb)); });
      }
      residues(1, [&](int ra, int rb) { d->Add(part->CommonPairGroups(0, i, ra, rb)); });
    }
    for (int t = 1; t < TemplateRotations::kThetaLevels; ++t) {
      for (int first = 0; first < steps; first += 1 << t) {
        for (int level = 0; level <= TemplateRotations::kSweptLevels; ++level) {
          residues(level, [&](int ra, int rb) {
            d->Add(part->SweptBlockGroups(t, first, level, ra, rb));
          });
        }
        residues(0, [&](int ra, int rb) { d->Add(part->CommonBlockGroups(t, first, ra, rb)); });
        residues(1, [&](int ra, int rb) { d->Add(part->CommonPairGroups(t, first, ra, rb)); });
      }
    }
  }
}

int Run(int argc, char** argv) {
  int repeat = 5;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) {
      repeat = std::atoi(argv[++i]);
    } else if (!a.empty() && a[0] != '-') {
      paths.push_back(a);
    } else {
      std::printf(
          "usage: setup_bench [--repeat N] [TEMPLATE.bt ...]\n"
          "Times an estimator's set-up per template (rotations, search tables, surface\n"
          "normals) and digests what it makes.\n"
          "  --repeat N   runs per measurement, median reported (5)\n"
          "  TEMPLATE.bt  templates to set up (default: the shipped ones)\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (repeat < 1) {
    std::fprintf(stderr, "setup_bench: --repeat must be >= 1\n");
    return 2;
  }
  if (paths.empty()) {
    for (const char* name : {"standing", "right_arm_raised"}) {
      paths.push_back(std::string(HPOSE_TEMPLATE_DIR) + "/" + name + ".bt");
    }
  }
  const EstimatorOptions options = DefaultEstimatorOptions();
  std::printf(
      "Set-up per template, thread CPU time, median of %d run(s); tables: every table "
      "MakeTables makes (theta levels 1-%d)\n\n",
      repeat, options.exact.top_theta_level);
  std::printf(
      "| template | voxels | rotations ms | tables ms | table MB | surface ms | surface points | "
      "rotations digest | tables digest | normals digest |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& path : paths) {
    Result<VoxelTemplate> tpl = LoadTemplate(path);
    if (!tpl.ok()) {
      std::fprintf(stderr, "setup_bench: %s: %s\n", path.c_str(), tpl.error().message.c_str());
      return 1;
    }
    std::vector<double> rotations_ms, tables_ms, surface_ms;
    Digest rotations, tables, normals;
    size_t surface_points = 0;
    for (int r = 0; r < repeat; ++r) {
      double t0 = ThreadCpuMs();
      const TemplateRotations rot(*tpl, options.lattice);
      rotations_ms.push_back(ThreadCpuMs() - t0);
      t0 = ThreadCpuMs();
      rot.MakeTables(options.exact.top_theta_level, 0, options.lattice.angle_steps);
      tables_ms.push_back(ThreadCpuMs() - t0);
      t0 = ThreadCpuMs();
      const SurfaceModel surface(*tpl, options.refine.surface_spacing_m);
      surface_ms.push_back(ThreadCpuMs() - t0);
      if (r == 0) {
        DigestRotations(rot, &rotations);
        DigestTables(rot, &tables);
        normals.Add(surface.normals().data(), surface.normals().size() * sizeof(float) * 3);
        surface_points = surface.normals().size();
      }
    }
    const std::string name = path.substr(path.find_last_of('/') + 1);
    std::printf("| %s | %zu | %.1f | %.1f | %.1f | %.1f | %zu | %016llx | %016llx | %016llx |\n",
                name.c_str(), tpl->voxels.size(), Median(rotations_ms), Median(tables_ms),
                tables.bytes / 1e6, Median(surface_ms), surface_points,
                static_cast<unsigned long long>(rotations.h),
                static_cast<unsigned long long>(tables.h),
                static_cast<unsigned long long>(normals.h));
  }
  return 0;
}

}  // namespace
}  // namespace hpose::bench

int main(int argc, char** argv) { return hpose::bench::Run(argc, argv); }
