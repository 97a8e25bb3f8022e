// SPDX-License-Identifier: GPL-2.0-or-later
// Per-atom kernels of the physics core, timed on the scene of benchmarks/in.cost (20 000 spheres of
// 30 um at random in a 4 x 4 x 20 mm box): the time per sphere of what compute concentration/grid
// and the Di Felice law do each step. Ratios between kernels, or between two builds run back to back.
//   build/bench_core_kernels [--benchmark_repetitions=5]
#include "sediment/batch_math.hpp"
#include "sediment/concentration.hpp"
#include "sediment/drag.hpp"
#include "sediment/integrator.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <memory>
#include <random>
#include <vector>

namespace {

constexpr int spheres = 20000;
constexpr double radius = 1.5e-5;
constexpr double box[3] = {0.004, 0.004, 0.02};

// Rows of three coordinates in one block, as LAMMPS keeps positions.
std::unique_ptr<double[][3]> centres()
{
  std::mt19937_64 random(11);
  auto out = std::make_unique<double[][3]>(spheres);
  for (int i = 0; i < spheres; ++i)
    for (int d = 0; d < 3; ++d) out[i][d] = std::uniform_real_distribution<double>(0.0, box[d])(random);
  return out;
}

sediment::Grid layer_grid()
{
  sediment::Grid grid{};
  for (int d = 0; d < 3; ++d) grid.axes[d] = {0.0, box[d], 1, true};
  grid.axes[2] = {0.0, box[2] / 400, 400, true};
  grid.resolved[0] = grid.resolved[1] = false;
  grid.resolved[2] = true;
  return grid;
}

sediment::Grid cell_grid()
{
  const int counts[3] = {20, 20, 100};
  sediment::Grid grid{};
  for (int d = 0; d < 3; ++d) {
    grid.axes[d] = {0.0, box[d] / counts[d], counts[d], true};
    grid.resolved[d] = true;
  }
  return grid;
}

void deposit(benchmark::State &state, const sediment::Grid &grid)
{
  const auto at = centres();
  std::vector<double> values(grid.cells());
  for (auto _ : state) {
    for (int i = 0; i < spheres; ++i) sediment::add_sphere_to_grid(grid, at[i], radius, values.data());
    benchmark::DoNotOptimize(values.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}

// The field read at every sphere in one call, as compute concentration/grid reads group all.
void interpolate(benchmark::State &state, const sediment::Grid &grid)
{
  const auto at = centres();
  std::vector<double> values(grid.cells(), 0.01), out(spheres);
  for (int i = 0; i < spheres; ++i) sediment::add_sphere_to_grid(grid, at[i], radius, values.data());
  for (auto _ : state) {
    sediment::grid_values_at(grid, values.data(), at.get(), spheres, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}

// Every sphere in one call, as compute concentration/grid deposits group all, the rows in LAMMPS's
// order after its spatial sort (atom_modify sort, by default every 1000 steps): neighbours in turn,
// so that consecutive spheres mostly add to the same layer.
void deposit_sorted(benchmark::State &state, const sediment::Grid &grid)
{
  const auto random_order = centres();
  std::vector<int> order(spheres);
  for (int i = 0; i < spheres; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return random_order[a][2] < random_order[b][2]; });
  auto at = std::make_unique<double[][3]>(spheres);
  for (int i = 0; i < spheres; ++i) std::copy_n(random_order[order[i]], 3, at[i]);
  const std::vector<double> radii(spheres, radius);
  std::vector<double> values(grid.cells());
  for (auto _ : state) {
    sediment::add_spheres_to_grid(grid, at.get(), radii.data(), nullptr, spheres, values.data());
    benchmark::DoNotOptimize(values.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}

void LayerDeposit(benchmark::State &state) { deposit(state, layer_grid()); }
void LayerDepositSorted(benchmark::State &state) { deposit_sorted(state, layer_grid()); }
void LayerInterpolation(benchmark::State &state) { interpolate(state, layer_grid()); }
void CellDeposit(benchmark::State &state) { deposit(state, cell_grid()); }
void CellInterpolation(benchmark::State &state) { interpolate(state, cell_grid()); }

// The Di Felice curve at the Reynolds numbers and voidages of a settling suspension, one sphere at a
// time (DragModel::curve) or a block of 32 at a time (DragModel::curves, as the integrator does).
void di_felice(benchmark::State &state, bool blocks)
{
  const sediment::DragModel model(sediment::DragLaw::DiFelice, {998.2, 1.002e-3, 0.0});
  std::mt19937_64 random(5);
  std::vector<double> re(spheres), voidage(spheres);
  for (int i = 0; i < spheres; ++i) {
    re[i] = std::uniform_real_distribution<double>(1e-3, 1.0)(random);
    voidage[i] = std::uniform_real_distribution<double>(0.9, 1.0)(random);
  }
  std::vector<sediment::DragCurve> curves(spheres);
  for (auto _ : state) {
    if (blocks)
      for (int i = 0; i < spheres; i += 32) model.curves(&re[i], &voidage[i], &curves[i], std::min(32, spheres - i));
    else
      for (int i = 0; i < spheres; ++i) curves[i] = model.curve(re[i], voidage[i]);
    benchmark::DoNotOptimize(curves.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}
void DiFeliceCurve(benchmark::State &state) { di_felice(state, false); }
void DiFeliceCurves(benchmark::State &state) { di_felice(state, true); }

// e^-z, phi1 and phi2 over the rates of a step near the relaxation time: one by one (phis) or 64
// at a time (phis_many, as the integrator takes a block's rates along and across the slip).
void phi_functions(benchmark::State &state, bool blocks)
{
  std::mt19937_64 random(7);
  std::vector<double> z(spheres);
  for (double &value : z) value = std::uniform_real_distribution<double>(0.1, 3.0)(random);
  std::vector<double> decay(spheres), phi1(spheres), phi2(spheres);
  for (auto _ : state) {
    if (blocks) {
      for (int i = 0; i < spheres; i += 64)
        sediment::phis_many(&z[i], &decay[i], &phi1[i], &phi2[i], std::min(64, spheres - i));
    } else {
      for (int i = 0; i < spheres; ++i) {
        const sediment::Phi p = sediment::phis(z[i]);
        decay[i] = p.decay;
        phi1[i] = p.phi1;
        phi2[i] = p.phi2;
      }
    }
    benchmark::DoNotOptimize(decay.data());
    benchmark::DoNotOptimize(phi1.data());
    benchmark::DoNotOptimize(phi2.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}
void Phis(benchmark::State &state) { phi_functions(state, false); }
void PhisMany(benchmark::State &state) { phi_functions(state, true); }

// The drag step of a nonlinear law (30 um quartz in water, slips around the terminal speed of
// 0.74 mm/s, the step 1e-4 s, or dt = 10^k tau with the argument k): a block of one sphere at a
// time (nonlinear_step_initial), blocks of DragBlock::capacity (as fix nve/sphere/fluid steps them)
// on the fastest kind here, on AVX2 or on SSE2 (the default build's 2-wide arithmetic and
// exponentials), or the step in pieces one sphere at a time (set_valued_step_initial, which a law
// with a Cd jump or a yield stress took before blocks).
enum class Stepping { OneByOne, Blocks, InPieces };
void nonlinear_step(benchmark::State &state, sediment::DragLaw law, sediment::Fluid fluid, Stepping stepping,
                    sediment::BatchMath kind = sediment::batch_math_kind(), double dt = 1e-4)
{
  const sediment::DragModel model(law, fluid);
  const double diameter = 2 * radius, inverse_mass = 1.0 / (2650 * sediment::pi / 6 * diameter * diameter * diameter);
  const double flow[3] = {0.0, 0.0, 0.0};
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> slip(-1e-3, 1e-3), accel(-6.0, 0.0);
  std::vector<std::array<double, 3>> v(spheres), a(spheres), dx(spheres);
  for (int i = 0; i < spheres; ++i)
    for (int k = 0; k < 3; ++k) {
      v[i][k] = slip(random);
      a[i][k] = k == 2 ? accel(random) : 0.0;
    }
  sediment::SphereDrag drag;
  drag.model = &model;
  drag.diameter = diameter;
  sediment::DragBlock block;
  block.set_law(model, flow);
  for (auto _ : state) {
    auto u = v;    // the same start each time
    if (stepping == Stepping::Blocks) {
      for (int start = 0; start < spheres; start += sediment::DragBlock::capacity) {
        const int end = std::min(spheres, start + sediment::DragBlock::capacity);
        for (int i = start; i < end; ++i) block.add(drag, inverse_mass, a[i].data(), u[i].data());
        block.step(dt, kind);
        for (int i = start; i < end; ++i) {
          block.velocity(i - start, u[i].data());
          block.displacement(i - start, dx[i].data());
        }
        block.clear();
      }
    } else if (stepping == Stepping::OneByOne) {
      for (int i = 0; i < spheres; ++i)
        sediment::nonlinear_step_initial(drag, inverse_mass, a[i].data(), flow, dt, u[i].data(), dx[i].data());
    } else {
      for (int i = 0; i < spheres; ++i)
        sediment::set_valued_step_initial(drag, 1.0 / inverse_mass, a[i].data(), flow, dt, u[i].data(), dx[i].data());
    }
    benchmark::DoNotOptimize(u.data());
    benchmark::DoNotOptimize(dx.data());
  }
  state.SetItemsProcessed(state.iterations() * spheres);
}
constexpr sediment::Fluid water{998.2, 1.002e-3, 0.0};
// A yield stress whose static drag holds up about half the immersed weight (benchmarks/in.cost's bingham scene).
constexpr sediment::Fluid bingham{998.2, 1.002e-3, 0.01};
void SmoothStepOneByOne(benchmark::State &state) { nonlinear_step(state, sediment::DragLaw::Dallavalle, water, Stepping::OneByOne); }
void SmoothStepBlocks(benchmark::State &state) { nonlinear_step(state, sediment::DragLaw::Dallavalle, water, Stepping::Blocks); }
// The blocks at dt/tau = 10^k (tau = m / (3 pi mu d), 132 us): the regimes users run, from a bed's
// contact-limited steps (k = -4) to the fine grains of a sedimentation test (k = 4).
void SmoothStepBlocksAtRatio(benchmark::State &state)
{
  const double tau = sediment::relaxation_time(sediment::DragModel(sediment::DragLaw::Stokes, water), 2 * radius, 2650);
  nonlinear_step(state, sediment::DragLaw::Dallavalle, water, Stepping::Blocks, sediment::batch_math_kind(),
                 tau * std::pow(10.0, static_cast<double>(state.range(0))));
}
void SmoothStepBlocksAVX2(benchmark::State &state)
{
  nonlinear_step(state, sediment::DragLaw::Dallavalle, water, Stepping::Blocks, sediment::BatchMath::AVX2);
}
void SmoothStepBlocksSSE2(benchmark::State &state)
{
  nonlinear_step(state, sediment::DragLaw::Dallavalle, water, Stepping::Blocks, sediment::BatchMath::SSE2);
}
void SchillerNaumannInPieces(benchmark::State &state)
{
  nonlinear_step(state, sediment::DragLaw::SchillerNaumann, water, Stepping::InPieces);
}
void SchillerNaumannBlocks(benchmark::State &state)
{
  nonlinear_step(state, sediment::DragLaw::SchillerNaumann, water, Stepping::Blocks);
}
void ZhangLiBinghamInPieces(benchmark::State &state)
{
  nonlinear_step(state, sediment::DragLaw::ZhangLi, bingham, Stepping::InPieces);
}
void ZhangLiBinghamBlocks(benchmark::State &state) { nonlinear_step(state, sediment::DragLaw::ZhangLi, bingham, Stepping::Blocks); }

BENCHMARK(LayerDeposit);
BENCHMARK(LayerDepositSorted);
BENCHMARK(LayerInterpolation);
BENCHMARK(CellDeposit);
BENCHMARK(CellInterpolation);
BENCHMARK(DiFeliceCurve);
BENCHMARK(DiFeliceCurves);
BENCHMARK(Phis);
BENCHMARK(PhisMany);
BENCHMARK(SmoothStepOneByOne);
BENCHMARK(SmoothStepBlocks);
BENCHMARK(SmoothStepBlocksAtRatio)->DenseRange(-4, 4, 1);
BENCHMARK(SmoothStepBlocksAVX2);
BENCHMARK(SmoothStepBlocksSSE2);
BENCHMARK(SchillerNaumannInPieces);
BENCHMARK(SchillerNaumannBlocks);
BENCHMARK(ZhangLiBinghamInPieces);
BENCHMARK(ZhangLiBinghamBlocks);

}    // namespace

BENCHMARK_MAIN();
