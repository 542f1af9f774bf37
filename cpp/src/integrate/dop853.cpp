// SPDX-License-Identifier: BSD-3-Clause
// DOP853: Dormand-Prince 8(5,3) with 7th-order dense output (integrators.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "adaptive_run.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/integrate/integrators.hpp"

namespace armdyn {

namespace {

// DOP853 coefficients (Hairer, Norsett & Wanner, Solving ODEs I, II.10; the tables of Hairer's
// dop853.f: 12 stages, the step's end f(t + h, y1) as stage 13 and three stages more for the
// 7th-order dense output). b = a[12][0..11]; e5 and e3 give the 5th- and 3rd-order error
// estimates; d the dense-output rows beyond the first three.
namespace dop853 {
constexpr double c[16] = {0,
                          0.05260015195876773,
                          0.0789002279381516,
                          0.1183503419072274,
                          0.2816496580927726,
                          0.3333333333333333,
                          0.25,
                          0.3076923076923077,
                          0.6512820512820513,
                          0.6,
                          0.8571428571428571,
                          1.0,
                          1.0,
                          0.1,
                          0.2,
                          0.7777777777777778};
constexpr double a[16][16] = {
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.05260015195876773, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.0197250569845379, 0.0591751709536137, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.02958758547680685, 0, 0.08876275643042054, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.2413651341592667, 0, -0.8845494793282861, 0.924834003261792, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
     0},
    {0.037037037037037035, 0, 0, 0.17082860872947386, 0.12546768756682242, 0, 0, 0, 0, 0, 0, 0, 0,
     0, 0, 0},
    {0.037109375, 0, 0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0, 0, 0, 0, 0, 0, 0,
     0, 0, 0},
    {0.03709200011850479, 0, 0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402,
     0.008273789163814023, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.6241109587160757, 0, 0, -3.3608926294469414, -0.868219346841726, 27.59209969944671,
     20.154067550477894, -43.48988418106996, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.47766253643826434, 0, 0, -2.4881146199716677, -0.590290826836843, 21.230051448181193,
     15.279233632882423, -33.28821096898486, -0.020331201708508627, 0, 0, 0, 0, 0, 0, 0},
    {-0.9371424300859873, 0, 0, 5.186372428844064, 1.0914373489967295, -8.149787010746927,
     -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0, 0, 0, 0, 0,
     0},
    {2.273310147516538, 0, 0, -10.53449546673725, -2.0008720582248625, -17.9589318631188,
     27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303,
     0.6433927460157636, 0, 0, 0, 0, 0},
    {0.054293734116568765, 0, 0, 0, 0, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
     0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259, 0, 0, 0, 0},
    {0.056167502283047954, 0, 0, 0, 0, 0, 0.25350021021662483, -0.2462390374708025,
     -0.12419142326381637, 0.15329179827876568, 0.00820105229563469, 0.007567897660545699,
     -0.008298, 0, 0, 0},
    {0.03183464816350214, 0, 0, 0, 0, 0.028300909672366776, 0.053541988307438566,
     -0.05492374857139099, 0, 0, -0.00010834732869724932, 0.0003825710908356584,
     -0.00034046500868740456, 0.1413124436746325, 0, 0},
    {-0.42889630158379194, 0, 0, 0, 0, -4.697621415361164, 7.683421196062599, 4.06898981839711,
     0.3567271874552811, 0, 0, 0, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987, 0},
};
constexpr double e5[12] = {0.01312004499419488,
                           0,
                           0,
                           0,
                           0,
                           -1.2251564463762044,
                           -0.4957589496572502,
                           1.6643771824549864,
                           -0.35032884874997366,
                           0.3341791187130175,
                           0.08192320648511571,
                           -0.022355307863886294};
constexpr double e3[12] = {-0.18980075407240762,
                           0,
                           0,
                           0,
                           0,
                           4.450312892752409,
                           1.8915178993145003,
                           -5.801203960010585,
                           -0.4226823213237919,
                           -0.1521609496625161,
                           0.20136540080403034,
                           0.02265179219836082};
constexpr double d[4][16] = {
    {-8.428938276109013, 0, 0, 0, 0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207,
     2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688,
     -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894},
    {10.427508642579134, 0, 0, 0, 0, 242.28349177525817, 165.20045171727028, -374.5467547226902,
     -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229,
     15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408},
    {19.985053242002433, 0, 0, 0, 0, -387.0373087493518, -189.17813819516758, 527.8081592054236,
     -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443,
     -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279},
    {-25.69393346270375, 0, 0, 0, 0, -154.18974869023643, -231.5293791760455, 357.6391179106141,
     93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605, -43.53345659001114,
     96.32455395918828, -39.17726167561544, -149.72683625798564},
};
}  // namespace dop853

// out = y + h sum_{j < s} w[j] k[j]
inline void stage_point(VecX& out, const VecX& y, double h, const double* w, int s,
                        const std::array<VecX, 16>& k) {
  out = y;
  for (int j = 0; j < s; ++j)
    if (w[j] != 0.0) out += (h * w[j]) * k[j];
}

}  // namespace

void integrate_dop853(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& st, IntegratorWork* work) {
  IntegratorWork local;
  IntegratorWork& w = work ? *work : local;
  namespace C = dop853;
  // step-size control: Hairer's dop853 defaults (no PI term)
  constexpr double safe = 0.9, fac_min = 0.333, fac_max = 6.0, expo = 1.0 / 8.0;
  const long n = y.size();
  std::array<VecX, 16>& k = w.stages;
  for (VecX& ki : k)
    if (ki.size() != n) ki.resize(n);
  std::array<VecX, 7>& r = w.dense;  // y(t + th h) = y + th (r0 + (1-th)(r1 + th(r2 + ...)))
  for (VecX& ri : r)
    if (ri.size() != n) ri.resize(n);
  VecX &yt = w.vec(23, n), &y1 = w.vec(24, n), &yp = w.vec(25, n);
  detail::AdaptiveRun run("dop853", sys, opt, t0, t1, n, w);
  double &t = run.t, &h = run.h;
  run.start(sys, y, k[0], yt, k[1], 8, st);
  auto stages = [&](int from, int to) {
    for (int s = from; s < to; ++s) {
      stage_point(yt, y, h, C::a[s], s, k);
      sys.rhs(t + C::c[s] * h, yt, k[s]);
    }
  };

  while (t < t1) {
    run.guard(st);
    const bool stages_ok = detail::evaluates([&] { stages(1, 12); }, h, fac_min, run.hmin);
    st.rhs_evals += 11;
    if (!stages_ok) {
      run.reject(h * fac_min, st);
      continue;
    }
    stage_point(y1, y, h, C::a[12], 12, k);
    // error: the 5th-order estimate, damped by the 3rd-order one where the latter is much
    // larger (Hairer's err^2 / sqrt(err^2 + 0.01 err3^2)), in the scaled max-norm of err_norm
    double n5 = 0.0, n3 = 0.0;
    for (long i = 0; i < n; ++i) {
      double s5 = 0.0, s3 = 0.0;
      for (int j = 0; j < 12; ++j) {
        s5 += C::e5[j] * k[j][i];
        s3 += C::e3[j] * k[j][i];
      }
      const double sc = opt.atol + opt.rtol * std::max(std::abs(y[i]), std::abs(y1[i]));
      n5 = std::max(n5, std::abs(h * s5) / sc);
      n3 = std::max(n3, std::abs(h * s3) / sc);
    }
    const double deno = n5 * n5 + 0.01 * n3 * n3;
    const double en = deno > 0 ? n5 * n5 / std::sqrt(deno) : 0.0;
    if (!std::isfinite(en)) throw SolverError(msg("dop853: non-finite error estimate at t=", t));
    const double fac11 = std::pow(en, expo);
    if (en > 1.0) {
      run.reject(h / std::min(1.0 / fac_min, fac11 / safe), st);
      continue;
    }
    // accepted: project the end point and evaluate there (stage 13, the next step's first); a
    // projection that fails rejects the step
    yp = y1;
    if (!detail::evaluates([&] { sys.project_and_rhs(t + h, yp, k[12]); }, h, fac_min, run.hmin)) {
      run.reject(h * fac_min, st);
      continue;
    }
    ++st.rhs_evals;
    y1 = yp;  // the dense output ends where the next step starts
    const double fac = std::clamp(fac11 / safe, 1.0 / fac_max, 1.0 / fac_min);
    double hnew = std::min(h / fac, run.hmax);
    if (run.last_rejected) hnew = std::min(hnew, h);
    double tn = run.step_end();
    // dense output only where it is used: an output time inside the step or a sign change of
    // an event function (three more right-hand sides)
    const bool events = run.sign_change(sys, tn, y1);
    if (events || run.output_inside(tn)) {
      const bool dense_ok = detail::evaluates([&] { stages(13, 16); }, h, fac_min, run.hmin);
      st.rhs_evals += 3;
      if (!dense_ok) {  // nothing of the step is kept: y, t and k[0] are unchanged
        run.reject(h * fac_min, st);
        continue;
      }
      r[0] = y1 - y;
      r[1] = h * k[0] - r[0];
      r[2] = 2.0 * r[0] - h * (k[12] + k[0]);
      for (int row = 0; row < 4; ++row) {
        VecX& rr = r[3 + row];
        rr.setZero();
        for (int j = 0; j < 16; ++j)
          if (C::d[row][j] != 0.0) rr += (h * C::d[row][j]) * k[j];
      }
    }
    auto dense = [&](double th, VecX& out) {
      const double th1 = 1.0 - th;
      out =
          y +
          th * (r[0] +
                th1 * (r[1] + th * (r[2] + th1 * (r[3] + th * (r[4] + th1 * (r[5] + th * r[6]))))));
    };
    if (run.accept(sys, tn, dense, events, y, y1, st)) {  // an event cut the step
      sys.project_and_rhs(tn, y, k[0]);
      ++st.rhs_evals;
    } else {
      std::swap(k[0], k[12]);
    }
    run.signs_after_events(sys, tn, y);
    run.advance(sys, tn, y, hnew, st);
  }
}

}  // namespace armdyn
