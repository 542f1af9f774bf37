// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/block_sparse.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <queue>
#include <set>
#include <sstream>
#include <type_traits>
#include <utility>

#include "armdyn/errors.hpp"
#include "armdyn/poll.hpp"

namespace armdyn {

namespace {

// The row blocks' adjacency in A: blocks g and h (both live) touch a common body
std::vector<std::set<int>> block_neighbours(const ConstraintEval& ce,
                                            const std::vector<char>& live) {
  std::vector<std::set<int>> nbr(ce.blocks.size());
  for (const auto& list : ce.body_blocks)
    for (const auto& [g, sg] : list)
      for (const auto& [h, sh] : list)
        if (g != h && live[g] && live[h]) nbr[g].insert(h);
  return nbr;
}

// The elimination of the live blocks by greedy minimum degree, the degree weighted by the
// neighbours' row counts, ties by index: the order, each step's neighbours (the blocks of its
// column of L), and the fill (blocks of L absent from A, and the blocks that receive it)
struct Elimination {
  std::vector<int> order;
  std::vector<std::vector<int>> cols_blk;
  std::set<int> fill_rows_blocks;
  long fill_blocks = 0;
};

Elimination eliminate_by_minimum_degree(std::vector<std::set<int>> nbr,
                                        const std::vector<char>& live,
                                        const std::vector<int>& size) {
  const int nblk = static_cast<int>(nbr.size());
  const std::vector<std::set<int>> original = nbr;
  Elimination e;
  int remaining = 0;
  for (int g = 0; g < nblk; ++g) remaining += live[g];
  std::vector<char> done(nblk, 0);
  // the blocks by (weighted degree, index) in a heap with lazy deletion: an entry is current
  // while its degree equals the block's (degrees change only next to an eliminated block)
  std::vector<long> degree(nblk, 0);
  auto weighted_degree = [&](int g) {
    long d = 0;
    for (int h : nbr[g]) d += size[h];
    return d;
  };
  using Entry = std::pair<long, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (int g = 0; g < nblk; ++g)
    if (live[g]) heap.emplace(degree[g] = weighted_degree(g), g);
  for (int step = 0; step < remaining; ++step) {
    poll_point();  // a long model's finalize stays interruptible
    while (done[heap.top().second] || heap.top().first != degree[heap.top().second]) heap.pop();
    const int best = heap.top().second;
    heap.pop();
    done[best] = 1;
    e.order.push_back(best);
    const std::vector<int> nb(nbr[best].begin(), nbr[best].end());
    e.cols_blk.push_back(nb);
    for (int a : nb) nbr[a].erase(best);
    for (int a : nb)
      for (int b : nb)
        if (a != b && nbr[a].insert(b).second && a < b && !original[a].count(b)) {
          ++e.fill_blocks;
          e.fill_rows_blocks.insert(a);
          e.fill_rows_blocks.insert(b);
        }
    for (int a : nb) heap.emplace(degree[a] = weighted_degree(a), a);
  }
  return e;
}

// the plan's path from its fill, and its one-line description
void describe_plan(KktPlan& p, int np) {
  std::ostringstream os;
  if (p.nrows == 0) {
    p.path = KktPath::Dense;
    os << "no constraint rows";
    p.description = os.str();
    return;
  }
  if (p.fill_blocks == 0)
    p.path = KktPath::Tree;
  else if (p.fill_blocks <= np)
    p.path = KktPath::TreeLoops;  // loop closures: fill along the loops, still linear in size
  else
    p.path = KktPath::Sparse;
  if (p.path == KktPath::Tree)
    os << "tree: block elimination leaves first, no fill (O(n))";
  else if (p.path == KktPath::TreeLoops)
    os << "tree + loops: block elimination leaves first, fill of " << p.fill_blocks
       << " blocks along the loops (" << p.loop_rows << " rows)";
  else
    os << "general sparse: minimum-degree block elimination, fill " << p.fill_blocks << " blocks";
  os << "; " << np << " row blocks, " << p.factor_entries << " factor entries, ~" << p.flops
     << " flops per factorisation";
  p.description = os.str();
}

}  // namespace

KktPlan plan_kkt(const Model& m, int nrows) {
  ConstraintEval ce;
  ce.init(m);
  KktPlan p;
  p.nrows = nrows;
  const int nblk = static_cast<int>(ce.blocks.size());
  std::vector<char> live(nblk, 0);
  std::vector<int> size(nblk, 0);
  for (int g = 0; g < nblk; ++g) {
    live[g] = ce.blocks[g].row0 < nrows;
    size[g] = ce.blocks[g].nrows;
  }
  const Elimination e = eliminate_by_minimum_degree(block_neighbours(ce, live), live, size);
  p.fill_blocks = e.fill_blocks;
  const int np = static_cast<int>(e.order.size());
  p.order = e.order;
  p.pos.assign(nblk, -1);
  for (int k = 0; k < np; ++k) p.pos[e.order[k]] = k;
  p.cols.resize(np);
  for (int k = 0; k < np; ++k) {
    for (int g : e.cols_blk[k]) p.cols[k].push_back(p.pos[g]);
    std::sort(p.cols[k].begin(), p.cols[k].end());
    const long s = size[e.order[k]];
    long r = 0;
    for (int i : p.cols[k]) r += size[e.order[i]];
    p.factor_entries += s * (s + 1) / 2 + s * r;
    p.flops += s * s * s / 3 + s * s * r + s * r * r;
  }
  for (int g : e.fill_rows_blocks) p.loop_rows += size[g];
  describe_plan(p, np);
  return p;
}

const KktPlans& kkt_plans(const Model& m) {
  return m.derived.get<KktPlans>([&] {
    KktPlans p;
    p.all = plan_kkt(m, m.nc);
    if (m.nc_joint != m.nc) p.joint = plan_kkt(m, m.nc_joint);
    return p;
  });
}

const char* kkt_path_name(KktPath path) {
  switch (path) {
    case KktPath::Tree:
      return "tree";
    case KktPath::TreeLoops:
      return "tree+loops";
    case KktPath::Sparse:
      return "sparse";
    case KktPath::Dense:
      return "dense";
    case KktPath::None:
      break;
  }
  return "";
}

KktPath kkt_path(const Model& m) {
  if (m.nc == 0) return KktPath::None;
  if (m.redundant || m.force_dense_kkt) return KktPath::Dense;
  return kkt_plans(m).all.path;
}

std::string kkt_path_description(const Model& m) {
  if (m.nc == 0) return "no constraint rows";
  if (m.redundant) return "dense Schur complement, pivoted Cholesky (minimum-norm multipliers)";
  if (m.force_dense_kkt) return "dense Schur complement (forced)";
  return kkt_plans(m).all.description;
}

BlockSparseSchur::BlockSparseSchur(const Model& m, const KktPlan& plan) : m_(m) {
  ConstraintEval ce;
  ce.init(m);
  nrows_ = plan.nrows;
  if (plan.pos.size() != ce.blocks.size())
    throw SolverError("internal: the KKT plan does not match the model's constraint blocks");
  const int np = static_cast<int>(plan.order.size());
  col_.resize(np);
  std::map<std::pair<int, int>, int> off;  // (row position, column position) -> offset
  int total = 0;
  auto bsize = [&](int k) { return ce.blocks[plan.order[k]].nrows; };
  for (int k = 0; k < np; ++k) {
    Column& c = col_[k];
    c.row0 = ce.blocks[plan.order[k]].row0;
    c.size = bsize(k);
    c.diag = total;
    off[{k, k}] = total;
    total += c.size * c.size;
    c.sub_begin = static_cast<int>(sub_.size());
    c.nsub = static_cast<int>(plan.cols[k].size());
    for (int i : plan.cols[k]) {
      sub_.push_back({i, total});
      off[{i, k}] = total;
      total += bsize(i) * c.size;
    }
  }
  for (int k = 0; k < np; ++k) {
    Column& c = col_[k];
    c.upd_begin = static_cast<int>(upd_.size());
    for (int a = 0; a < c.nsub; ++a)
      for (int b = 0; b <= a; ++b) {
        const int pa = sub_[c.sub_begin + a].pos, pb = sub_[c.sub_begin + b].pos;
        upd_.push_back({a, b, off.at({pa, pb})});
      }
    c.nupd = static_cast<int>(upd_.size()) - c.upd_begin;
  }
  scaled_off_.assign(ce.blocks.size() * kMaxBlockBodies, -1);
  int njw = 0;
  for (int g = 0; g < static_cast<int>(ce.blocks.size()); ++g) {
    if (plan.pos[g] < 0) continue;
    const ConstraintBlock& b = ce.blocks[g];
    for (int sl = 0; sl < b.nbody; ++sl) {
      if (b.body[sl] == kGround) continue;
      scaled_off_[g * kMaxBlockBodies + sl] = njw;
      scaled_.push_back({g, sl, njw});
      njw += 6 * b.nrows;
    }
  }
  jw_.assign(njw, 0.0);
  for (int b = 0; b < m.nb; ++b)
    for (const auto& [g, sg] : ce.body_blocks[b])
      for (const auto& [h, sh] : ce.body_blocks[b]) {
        const int pg = plan.pos[g], ph = plan.pos[h];
        if (pg < 0 || ph < 0 || pg < ph) continue;
        asm_.push_back({b, g, sg, h, sh, scaled_off_[g * kMaxBlockBodies + sg], off.at({pg, ph})});
      }
  val_.assign(total, 0.0);
  weak_.reserve(m.nc);
  diag0_.assign(m.nc, 0.0);
  inv_diag_.assign(m.nc, 0.0);
}

namespace {
// f(std::integral_constant<int, N>{}) with N = n when n is one of Ns (kernels unrolled at
// compile time), N = 0 (the size at run time) otherwise
template <int... Ns, class F>
inline void with_size(int n, F&& f) {
  const bool hit = ((n == Ns ? (f(std::integral_constant<int, Ns>{}), true) : false) || ...);
  if (!hit) f(std::integral_constant<int, 0>{});
}
// the row counts of the common joint and gear blocks
template <class F>
inline void with_rows(int n, F&& f) {
  with_size<1, 5, 6>(n, f);
}

// T(sg x sh) += JW(sg x NC columns of a row-major sg x 6) Jh(sh x NC, rows `stride` apart)^T,
// column-major T; DIAG: lower triangle only. SG, SH > 0 fix the sizes at compile time.
template <int SG, int SH, bool DIAG, int NC>
inline void assemble(double* __restrict__ t, const double* __restrict__ jw,
                     const double* __restrict__ jh0, long stride, int sg_rt, int sh_rt) {
  const int sg = SG > 0 ? SG : sg_rt;
  const int sh = SH > 0 ? SH : sh_rt;
  for (int c = 0; c < sh; ++c) {
    const double* __restrict__ jh = jh0 + c * stride;
    for (int r = DIAG ? c : 0; r < sg; ++r) {
      const double* jr = jw + 6 * r;
      double x = jr[0] * jh[0];
      for (int k = 1; k < NC; ++k) x += jr[k] * jh[k];
      t[r + c * sg] += x;
    }
  }
}

// One body's term of the block (g, h): T(sg x sh) += (J_g W^-1)(sg x 6) J_h(sh x 6)^T. The
// rotational columns by products; the translational ones through the point-row structure
// (rows 0..2 of the block are eg I, resp. eh I, for eg, eh = +-1; 0: no such structure).
template <int SG, int SH, bool DIAG>
inline void assemble_pair(double* __restrict__ t, const double* __restrict__ jw,
                          const double* __restrict__ jh, long stride, int sg_rt, int sh_rt,
                          double eg, double eh, double wl) {
  const int sg = SG > 0 ? SG : sg_rt;
  const int sh = SH > 0 ? SH : sh_rt;
  if (eg == 0.0 && eh == 0.0) {
    assemble<SG, SH, DIAG, 6>(t, jw, jh, stride, sg, sh);
    return;
  }
  assemble<SG, SH, DIAG, 3>(t, jw + 3, jh + 3, stride, sg, sh);
  if (eg != 0.0 && eh != 0.0) {
    for (int i = 0; i < 3; ++i) t[i + i * sg] += eg * eh * wl;
  } else if (eg != 0.0) {
    // (J_g W^-1)_lin = eg w [I; 0]: T(i, c) += eg w J_h(c, i) for i < 3
    for (int c = 0; c < sh; ++c)
      for (int i = 0; i < 3; ++i) t[i + c * sg] += eg * wl * jh[c * stride + i];
  } else {
    // (J_h)_lin = eh [I; 0]: T(r, i) += eh (J_g W^-1)(r, i) for i < 3
    for (int i = 0; i < 3; ++i)
      for (int r = 0; r < sg; ++r) t[r + i * sg] += eh * jw[6 * r + i];
  }
}

// T(na x nb) -= La(na x s) Lb(nb x s)^T, column-major; DIAG: lower triangle only (na == nb).
// NA, NB, S > 0 fix the sizes at compile time (fully unrolled for the common joint blocks).
template <int NA, int NB, int S, bool DIAG>
inline void schur_update(double* __restrict__ T, const double* __restrict__ La,
                         const double* __restrict__ Lb, int na_rt, int nb_rt, int s_rt) {
  const int na = NA > 0 ? NA : na_rt;
  const int nb = NB > 0 ? NB : nb_rt;
  const int s = S > 0 ? S : s_rt;
  // each entry of T is read and written once (a sum over p in registers): no store-to-load
  // stalls between the rank-1 passes
  for (int cc = 0; cc < nb; ++cc) {
    double* __restrict__ t = T + cc * na;
    for (int r = DIAG ? cc : 0; r < na; ++r) {
      double x = La[r] * Lb[cc];
      for (int p = 1; p < s; ++p) x += La[r + p * na] * Lb[cc + p * nb];
      t[r] -= x;
    }
  }
}
// X(si x s) <- X L^-T with L (s x s) lower triangular, inv its reciprocal diagonal.
template <int SI, int S>
inline void trsm_right(double* __restrict__ X, const double* __restrict__ L,
                       const double* __restrict__ inv, int si_rt, int s_rt) {
  const int si = SI > 0 ? SI : si_rt;
  const int s = S > 0 ? S : s_rt;
  for (int j = 0; j < s; ++j) {
    double* __restrict__ xj = X + j * si;
    for (int r = 0; r < si; ++r) {
      double x = xj[r];
      for (int p = 0; p < j; ++p) x -= L[j + p * s] * X[r + p * si];
      xj[r] = x * inv[j];
    }
  }
}
}  // namespace

bool BlockSparseSchur::factor(const ConstraintEval& ce, const std::vector<Mat6>* winv,
                              double shift) {
  shift_ = shift;
  min_rel_ = 1.0;
  weak_.clear();
  std::fill(val_.begin(), val_.end(), 0.0);
  double* v = val_.data();
  // J_g,s W_b^-1 once per (block, slot), with W^-1 = diag(W_xx, W_ww) per body (W_xx = w I);
  // the translational part only where the block has no point-row structure
  for (const Scaled& sc : scaled_) {
    const ConstraintBlock& b = ce.blocks[sc.g];
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, 6, 6>> jw(
        jw_.data() + sc.off, b.nrows, 6);
    const auto J = b.J.middleCols<6>(6 * sc.slot);
    if (winv) {
      const Mat6& w = (*winv)[b.body[sc.slot]];
      if (!b.point_rows) jw.leftCols<3>() = J.leftCols<3>() * w(0, 0);
      jw.rightCols<3>().noalias() = J.rightCols<3>() * w.bottomRightCorner<3, 3>();
    } else {
      jw = J;
    }
  }
  // assembly: A(g, h) += (J_g,b W_b^-1) J_h,b^T over the bodies b the two blocks share (lower
  // triangle only on the diagonal blocks): the rotational columns by products, the translational
  // ones through the point-row structure (+-I on rows 0..2) where the blocks have it
  for (const Assembly& a : asm_) {
    const ConstraintBlock& bg = ce.blocks[a.g];
    const ConstraintBlock& bh = ce.blocks[a.h];
    const double* jw = jw_.data() + a.jw;
    const int sg = bg.nrows, sh = bh.nrows;
    const double* jh = bh.J.data() + 6 * a.sh;
    const long stride = bh.J.cols();
    double* t = v + a.target;
    const double eg = bg.point_rows ? (a.sg == 0 ? -1.0 : 1.0) : 0.0;
    const double eh = bh.point_rows ? (a.sh == 0 ? -1.0 : 1.0) : 0.0;
    const double wl = winv ? (*winv)[a.body](0, 0) : 1.0;
    if (a.g == a.h) {
      with_rows(sg,
                [&](auto N) { assemble_pair<N, N, true>(t, jw, jh, stride, sg, sh, eg, eh, wl); });
    } else {
      with_rows(sg, [&](auto NG) {
        with_rows(sh, [&](auto NH) {
          assemble_pair<NG, NH, false>(t, jw, jh, stride, sg, sh, eg, eh, wl);
        });
      });
    }
  }
  const int np = static_cast<int>(col_.size());
  for (int k = 0; k < np; ++k) {
    const Column& c = col_[k];
    for (int j = 0; j < c.size; ++j) {
      double& d = v[c.diag + j + j * c.size];
      diag0_[c.row0 + j] = d;
      d += shift * d;
    }
  }
  for (int k = 0; k < np; ++k) {
    bool ok = false;  // the block sizes of joints (1..6 rows) get unrolled kernels
    with_size<1, 2, 3, 4, 5, 6>(col_[k].size,
                                [&](auto N) { ok = this->factor_column<decltype(N)::value>(k); });
    if (!ok) return false;
  }
  return true;
}

template <int S>
bool BlockSparseSchur::factor_column(int k) {
  const Column& c = col_[k];
  const int s = S > 0 ? S : c.size;
  double* __restrict__ v = val_.data();
  double* __restrict__ L = v + c.diag;
  double* __restrict__ inv = inv_diag_.data() + c.row0;
  // dense Cholesky of the diagonal block, pivots against the row's diagonal. Computed as
  // L D L^T first (the unscaled columns U = L D in the lower triangle, L = U D^-1 in the upper
  // one, D in inv), so that only one division per pivot lies on the chain from one pivot to the
  // next; the square roots and the scaling to the Cholesky factor follow off that chain.
  for (int j = 0; j < s; ++j) {
    double d = L[j + j * s];
    for (int p = 0; p < j; ++p) d -= L[j + p * s] * L[p + j * s];
    const double d0 = diag0_[c.row0 + j];
    if (!(d > 1e-12 * d0)) return false;
    if (d < min_rel_ * d0) min_rel_ = d / d0;  // (divides only at a new minimum)
    // nearly dependent: the pivot at the shift's level (relative to the diagonal)
    if (shift_ > 0.0 && d < 10.0 * shift_ * d0) weak_.push_back(c.row0 + j);
    inv[j] = d;
    const double id = 1.0 / d;
    for (int i = j + 1; i < s; ++i) {
      double x = L[i + j * s];
      for (int p = 0; p < j; ++p) x -= L[i + p * s] * L[p + j * s];
      L[i + j * s] = x;
      L[j + i * s] = x * id;
    }
  }
  // Cholesky: L_ij = U_ij / sqrt(d_j), L_jj = sqrt(d_j)
  for (int j = 0; j < s; ++j) {
    const double l = std::sqrt(inv[j]);
    L[j + j * s] = l;
    inv[j] = 1.0 / l;
    for (int i = j + 1; i < s; ++i) L[i + j * s] *= inv[j];
  }
  // blocks below: X <- X L_kk^-T, column by column
  for (int e = 0; e < c.nsub; ++e) {
    const Sub& sb = sub_[c.sub_begin + e];
    const int si = col_[sb.pos].size;
    double* X = v + sb.off;
    with_rows(si, [&](auto N) { trsm_right<N, S>(X, L, inv, si, s); });
  }
  // Schur updates of the later blocks: T(a, b) -= L(a, k) L(b, k)^T (lower triangle of the
  // diagonal blocks), with the row count of the common joint blocks fixed at compile time
  for (int e = 0; e < c.nupd; ++e) {
    const Update& u = upd_[c.upd_begin + e];
    const Sub& sa = sub_[c.sub_begin + u.a];
    const Sub& sb = sub_[c.sub_begin + u.b];
    const int na = col_[sa.pos].size, nb = col_[sb.pos].size;
    const double* La = v + sa.off;
    const double* Lb = v + sb.off;
    double* T = v + u.target;
    if (u.a == u.b) {
      with_rows(na, [&](auto N) { schur_update<N, N, S, true>(T, La, Lb, na, na, s); });
    } else {
      with_rows(na, [&](auto NA) {
        with_rows(nb, [&](auto NB) { schur_update<NA, NB, S, false>(T, La, Lb, na, nb, s); });
      });
    }
  }
  return true;
}

namespace {
// xk(s) -= X(ni x s)^T y(ni)
template <int NI, int S>
inline void sub_gemv_t(double* __restrict__ xk, const double* __restrict__ X,
                       const double* __restrict__ y, int ni_rt, int s_rt) {
  const int ni = NI > 0 ? NI : ni_rt;
  const int s = S > 0 ? S : s_rt;
  for (int j = 0; j < s; ++j) {
    const double* __restrict__ col = X + j * ni;
    double t = 0.0;
    for (int r = 0; r < ni; ++r) t += col[r] * y[r];
    xk[j] -= t;
  }
}
}  // namespace

template <int S>
void BlockSparseSchur::forward_column(int k, double* xd) const {
  const Column& c = col_[k];
  const int s = S > 0 ? S : c.size;
  const double* __restrict__ L = val_.data() + c.diag;
  double* __restrict__ xk = xd + c.row0;
  const double* __restrict__ inv = inv_diag_.data() + c.row0;
  for (int j = 0; j < s; ++j) {
    double t = xk[j];
    for (int p = 0; p < j; ++p) t -= L[j + p * s] * xk[p];
    xk[j] = t * inv[j];
  }
  for (int e = 0; e < c.nsub; ++e) {
    const Sub& sb = sub_[c.sub_begin + e];
    const int ni = col_[sb.pos].size;
    double* xi = xd + col_[sb.pos].row0;
    const double* X = val_.data() + sb.off;
    // xi -= X xk: the block update with a single column
    with_rows(ni, [&](auto N) { schur_update<N, 1, S, false>(xi, X, xk, ni, 1, s); });
  }
}

template <int S>
void BlockSparseSchur::backward_column(int k, double* xd) const {
  const Column& c = col_[k];
  const int s = S > 0 ? S : c.size;
  const double* __restrict__ L = val_.data() + c.diag;
  double* __restrict__ xk = xd + c.row0;
  for (int e = 0; e < c.nsub; ++e) {
    const Sub& sb = sub_[c.sub_begin + e];
    const int ni = col_[sb.pos].size;
    const double* xi = xd + col_[sb.pos].row0;
    const double* X = val_.data() + sb.off;
    with_rows(ni, [&](auto N) { sub_gemv_t<N, S>(xk, X, xi, ni, s); });
  }
  const double* __restrict__ inv = inv_diag_.data() + c.row0;
  for (int j = s - 1; j >= 0; --j) {
    double t = xk[j];
    for (int p = j + 1; p < s; ++p) t -= L[p + j * s] * xk[p];
    xk[j] = t * inv[j];
  }
}

void BlockSparseSchur::solve_in_place(VecX& x) const {
  double* xd = x.data();
  const int np = static_cast<int>(col_.size());
  for (int k = 0; k < np; ++k)
    with_rows(col_[k].size, [&](auto N) { this->forward_column<decltype(N)::value>(k, xd); });
  for (int k = np - 1; k >= 0; --k)
    with_rows(col_[k].size, [&](auto N) { this->backward_column<decltype(N)::value>(k, xd); });
}

}  // namespace armdyn
