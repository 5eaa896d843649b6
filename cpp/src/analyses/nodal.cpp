#include "spacar/analyses/nodal.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "spacar/kinematics/dynamics.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/elements/spatial.hpp"

namespace spacar {

NodalLayout::NodalLayout(const System& sys) {
  free_of.assign(sys.nx, -1);
  for (const auto* list : {&sys.x_calc, &sys.x_dyn})
    for (int g : *list) {
      free_of[g] = static_cast<int>(free.size());
      free.push_back(g);
    }
  row_of.assign(sys.ne, -1);
  for (int k : sys.defs_V)
    if (sys.def_class[k] != DefClass::Dynamic) {
      row_of[k] = static_cast<int>(rows.size());
      rows.push_back(k);
    }
  n_free = static_cast<int>(free.size());
  n_rows = static_cast<int>(rows.size());
  scale.resize(n_free + n_rows);
  for (int f = 0; f < n_free; ++f) scale[f] = sys.coord_is_length[free[f]] ? sys.length_scale : 1.0;
  for (int r = 0; r < n_rows; ++r) scale[n_free + r] = sys.def_is_length[rows[r]] ? sys.length_scale : 1.0;
}

namespace {

// out(:, j) += row · r_j (n x n, column-major): the outer product row rᵀ. The element sizes of
// the beams (6 coordinates planar, 14 spatial) with their loops unrolled at compile time; they
// run for every element in every Newton iteration.
template <int N>
void add_outer_fixed(const double* row, const double* r, double* out) {
  for (int j = 0; j < N; ++j) {
    const double rj = r[j];
    double* column = out + j * N;
    for (int i = 0; i < N; ++i) column[i] += row[i] * rj;
  }
}

void add_outer_rows(const double* row, const double* r, int n, double* out) {
  switch (n) {
    case 6: add_outer_fixed<6>(row, r, out); return;
    case 14: add_outer_fixed<14>(row, r, out); return;
    default:
      for (int j = 0; j < n; ++j) {
        const double rj = r[j];
        if (rj == 0.0) continue;
        double* column = out + static_cast<Eigen::Index>(j) * n;
        for (int i = 0; i < n; ++i) column[i] += row[i] * rj;
      }
  }
}

// out += scale B(a, :)ᵀ r (n x n; r: n values `stride` apart).
void add_outer(const Eigen::MatrixXd& B, int a, const double* r, Eigen::Index stride, double scale,
               Eigen::MatrixXd& out) {
  const int n = static_cast<int>(B.cols());
  // B's row a and r copied to contiguous arrays first (B's rows are strided).
  double stack[64];
  std::vector<double> heap(n > 32 ? 2 * n : 0);
  double* row = n > 32 ? heap.data() : stack;
  double* rs = row + n;
  for (int i = 0; i < n; ++i) {
    row[i] = B(a, i);
    rs[i] = scale * r[i * stride];
  }
  add_outer_rows(row, rs, n, out.data());
}

// Bᵀ C B over the element's constitutive deformations (C: its S or D; σ_a = Σ_b C_ab e_b for
// each constitutive a), the columns b of deformations that `layout` constrains left out when a
// layout is given: they do not move on the constrained space (their B rows vanish there), and
// without them the matrix keeps the symmetry of C.
void add_constitutive(const System& sys, const SystemElement& se, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                      double coefficient, const NodalLayout* layout, Eigen::MatrixXd& out) {
  if (coefficient == 0.0 || !se.has_constitutive) return;
  const int n = static_cast<int>(B.cols());
  // Written out: Eigen's outer products of B's strided rows copied each row to the heap, and
  // this runs for every element in every Newton iteration.
  double stack[32];
  std::vector<double> heap(n > 32 ? n : 0);
  double* cb = n > 32 ? heap.data() : stack;  // Σ_b C(a, b) B(b, :), one constitutive a at a time
  for (int a = 0; a < se.nd; ++a) {
    if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
    std::fill(cb, cb + n, 0.0);
    bool any = false;
    for (int b = 0; b < se.nd; ++b) {
      if (C(a, b) == 0.0 || (layout && layout->row_of[se.def_offset + b] >= 0)) continue;
      const double w = coefficient * C(a, b);
      for (int j = 0; j < n; ++j) cb[j] += w * B(b, j);
      any = true;
    }
    if (any) add_outer(B, a, cb, 1, 1.0, out);
  }
}

// −∂f/∂x of the gravity load of the element's mass (central differences, symmetrized: the load
// is the gradient of a potential), times the coefficient.
void add_gravity_stiffness(const System& sys, const SystemElement& se, const ElementWork& w, double coefficient,
                           Eigen::MatrixXd& out) {
  const int n = static_cast<int>(se.coords.size());
  Eigen::VectorXd xp = w.x, fp(n), fm(n);
  Eigen::MatrixXd J(n, n);
  for (int b = 0; b < n; ++b) {
    const double h = 1e-6 * std::max(1.0, std::abs(w.x[b]));
    xp[b] = w.x[b] + h;
    se.kernel->gravity(xp.data(), sys.gravity.data(), fp.data());
    xp[b] = w.x[b] - h;
    se.kernel->gravity(xp.data(), sys.gravity.data(), fm.data());
    xp[b] = w.x[b];
    J.col(b) = (fp - fm) / (2.0 * h);
  }
  out -= 0.5 * coefficient * (J + J.transpose());
}

// The element's part of H without the constitutive terms (the geometric stiffness, the loads'
// stiffness, the mass; local, n x n).
void element_rest(const System& sys, const Data& data, size_t i, const Eigen::VectorXd& sigma,
                  const NodalCoefficients& c, Eigen::MatrixXd& out) {
  const SystemElement& se = sys.elements[i];
  const ElementWork& w = data.work[i];
  const int n = static_cast<int>(se.coords.size());
  out.setZero(n, n);
  if (c.geometric != 0.0) {
    const double* s = sigma.data() + se.def_offset;
    if (std::any_of(s, s + se.nd, [](double v) { return v != 0.0; })) {
      se.kernel->stress_hessian(w.x.data(), s, out.data());
      out *= c.geometric;
    }
    if (se.has_mass && sys.gravity.squaredNorm() > 0.0 && c.load_factor != 0.0)
      add_gravity_stiffness(sys, se, w, c.geometric * c.load_factor, out);
  }
  if (c.mass != 0.0 && se.has_mass) out += c.mass * w.M;
}

// The element's part of H (local, n x n); `layout`: see add_constitutive.
void element_matrix(const System& sys, const Data& data, size_t i, const Eigen::VectorXd& sigma,
                    const NodalCoefficients& c, const NodalLayout* layout, Eigen::MatrixXd& out) {
  element_rest(sys, data, i, sigma, c, out);
  const SystemElement& se = sys.elements[i];
  add_constitutive(sys, se, data.work[i].B, se.S, c.stiffness, layout, out);
  add_constitutive(sys, se, data.work[i].B, se.D, c.damping, layout, out);
}

// Whether the element's Bᵀ C B of add_constitutive is symmetric for its S and D: C symmetric
// among the constitutive deformations, and no coupling of a constitutive deformation to a free
// one that is not constitutive (a LINE parameter of the linearization).
bool symmetric_constitutive(const System& sys, const SystemElement& se, const NodalLayout& layout) {
  if (!se.has_constitutive) return true;
  for (const Eigen::MatrixXd* C : {&se.S, &se.D})
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      for (int b = 0; b < se.nd; ++b) {
        if ((*C)(a, b) == 0.0 || layout.row_of[se.def_offset + b] >= 0) continue;
        if (!constitutive_class(sys.def_class[se.def_offset + b]) || (*C)(a, b) != (*C)(b, a)) return false;
      }
    }
  return true;
}

}  // namespace

Eigen::SparseMatrix<double> nodal_part(const System& sys, Data& data, const Eigen::VectorXd& sigma, unsigned part) {
  NodalCoefficients c;
  c.stiffness = part & kStiffness ? 1.0 : 0.0;
  c.geometric = part & kGeometric ? 1.0 : 0.0;
  c.mass = part & kMass ? 1.0 : 0.0;
  c.damping = part & kDamping ? 1.0 : 0.0;
  return nodal_matrix(sys, data, sigma, c);
}

Eigen::SparseMatrix<double> nodal_matrix(const System& sys, Data& data, const Eigen::VectorXd& sigma,
                                         const NodalCoefficients& c) {
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixXd local;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    element_matrix(sys, data, i, sigma, c, nullptr, local);
    const std::vector<int>& g = sys.elements[i].coords;
    for (int b = 0; b < local.cols(); ++b)
      for (int a = 0; a < local.rows(); ++a)
        if (local(a, b) != 0.0) entries.emplace_back(g[a], g[b], local(a, b));
  }
  if (c.mass != 0.0) {
    for (int g = 0; g < sys.nx; ++g)
      if (sys.point_mass[g] != 0.0) entries.emplace_back(g, g, c.mass * sys.point_mass[g]);
    for (size_t b = 0; b < sys.bodies.size(); ++b)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          entries.emplace_back(sys.bodies[b].coord + i, sys.bodies[b].coord + j, c.mass * data.body_M[b](i, j));
  }
  if (c.geometric != 0.0 && c.load_factor != 0.0)
    for (const Torque& t : sys.torques) {
      const Eigen::Matrix4d K = c.geometric * c.load_factor * t.stiffness();
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) entries.emplace_back(t.coord + i, t.coord + j, K(i, j));
    }
  Eigen::SparseMatrix<double> A(sys.nx, sys.nx);
  A.setFromTriplets(entries.begin(), entries.end());
  A.prune(0.0);
  return A;
}

Eigen::Vector4d nodal_energies(const System& sys, Data& data, const Eigen::VectorXd& sigma, const Eigen::VectorXd& v) {
  Eigen::Vector4d out = Eigen::Vector4d::Zero();  // K, G, M, D
  Eigen::VectorXd ve, de, c;
  Eigen::MatrixXd load;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const ElementWork& w = data.work[i];
    const int n = static_cast<int>(se.coords.size());
    ve.resize(n);
    for (int j = 0; j < n; ++j) ve[j] = v[se.coords[j]];
    if (se.has_constitutive) {
      de.noalias() = w.B * ve;
      for (int a = 0; a < se.nd; ++a) {
        if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
        out[0] += de[a] * se.S.row(a).dot(de);
        out[3] += de[a] * se.D.row(a).dot(de);
      }
    }
    const Eigen::VectorXd s = sigma.segment(se.def_offset, se.nd);
    if (s.any()) {
      c.resize(se.nd);
      se.kernel->convective(w.x.data(), ve.data(), c.data());  // vᵀ ∂²e_k/∂x² v
      out[1] += s.dot(c);
    }
    if (se.has_mass) {
      out[2] += ve.dot(w.M * ve);
      if (sys.gravity.squaredNorm() > 0.0) {
        load.setZero(n, n);
        add_gravity_stiffness(sys, se, w, 1.0, load);
        out[1] += ve.dot(load * ve);
      }
    }
  }
  for (int g = 0; g < sys.nx; ++g) out[2] += sys.point_mass[g] * v[g] * v[g];
  for (size_t b = 0; b < sys.bodies.size(); ++b) {
    const Eigen::Vector4d vb = v.segment<4>(sys.bodies[b].coord);
    out[2] += vb.dot(data.body_M[b] * vb);
  }
  for (const Torque& t : sys.torques) {
    const Eigen::Vector4d vb = v.segment<4>(t.coord);
    out[1] += vb.dot(t.stiffness() * vb);
  }
  return out;
}

Eigen::SparseMatrix<double> nodal_constraints(const System& sys, const Data& data, const NodalLayout& layout) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    for (int a = 0; a < se.nd; ++a) {
      const int r = layout.row_of[se.def_offset + a];
      if (r < 0) continue;
      for (size_t j = 0; j < se.coords.size(); ++j)
        if (data.work[i].B(a, j) != 0.0) entries.emplace_back(r, se.coords[j], data.work[i].B(a, j));
    }
  }
  Eigen::SparseMatrix<double> A(layout.n_rows, sys.nx);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

Eigen::SparseMatrix<double> nodal_deformation_jacobian(const System& sys, const Data& data) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    for (int a = 0; a < se.nd; ++a)
      for (size_t j = 0; j < se.coords.size(); ++j)
        if (B(a, j) != 0.0) entries.emplace_back(se.def_offset + a, se.coords[j], B(a, j));
  }
  Eigen::SparseMatrix<double> B(sys.ne, sys.nx);
  B.setFromTriplets(entries.begin(), entries.end());
  return B;
}

Eigen::SparseMatrix<double> nodal_constitutive(const System& sys, bool damping) {
  std::vector<Eigen::Triplet<double>> entries;
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    const Eigen::MatrixXd& C = damping ? se.D : se.S;
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      for (int b = 0; b < se.nd; ++b)
        if (C(a, b) != 0.0) entries.emplace_back(se.def_offset + a, se.def_offset + b, C(a, b));
    }
  }
  Eigen::SparseMatrix<double> S(sys.ne, sys.ne);
  S.setFromTriplets(entries.begin(), entries.end());
  return S;
}

Eigen::SparseMatrix<double> nodal_dof_map(const System& sys, const Data& data) {
  std::vector<Eigen::Triplet<double>> entries;
  const int nxd = static_cast<int>(sys.x_dyn.size());
  for (int j = 0; j < nxd; ++j) entries.emplace_back(j, sys.x_dyn[j], 1.0);
  for (size_t j = 0; j < sys.e_dyn.size(); ++j) {
    const int k = sys.e_dyn[j];
    const SystemElement& se = sys.elements[sys.e_element[k]];
    const Eigen::MatrixXd& B = data.work[sys.e_element[k]].B;
    for (size_t c = 0; c < se.coords.size(); ++c)
      if (B(k - se.def_offset, c) != 0.0) entries.emplace_back(nxd + static_cast<int>(j), se.coords[c], B(k - se.def_offset, c));
  }
  Eigen::SparseMatrix<double> E(sys.n_dof(), sys.nx);
  E.setFromTriplets(entries.begin(), entries.end());
  return E;
}

SaddlePoint::SaddlePoint(const System& sys, const NodalLayout& layout) : layout_(layout) {
  const int nf = layout.n_free;
  n_ = nf + layout.n_rows;
  // Symmetric unless torques (their load stiffness), slip rates (their derivatives are not
  // integrable) or an unsymmetric constitutive matrix make H unsymmetric.
  symmetric_ = sys.torques.empty();
  for (int k = 0; k < sys.ne; ++k) symmetric_ = symmetric_ && !sys.def_velocity_level[k];
  for (const SystemElement& se : sys.elements) symmetric_ = symmetric_ && symmetric_constitutive(sys, se, layout);
  kkt_.reset(n_, n_);
  element_scale_start_.push_back(0);
  std::vector<int> fi, cr;  // an element's free indices and constraint rows (reused)
  rest_start_.push_back(0);
  for (const SystemElement& se : sys.elements) {
    rest_start_.push_back(rest_start_.back() + static_cast<int>(se.coords.size() * se.coords.size()));
    for (int g : se.coords) element_scale_.push_back(layout.free_of[g] >= 0 ? layout.scale[layout.free_of[g]] : 1.0);
    element_scale_start_.push_back(static_cast<int>(element_scale_.size()));
    fi.resize(se.coords.size());
    cr.resize(se.nd);
    bool any_row = false;
    for (size_t j = 0; j < se.coords.size(); ++j) fi[j] = layout.free_of[se.coords[j]];
    for (int a = 0; a < se.nd; ++a) {
      const int r = layout.row_of[se.def_offset + a];
      cr[a] = r >= 0 ? nf + r : -1;
      any_row = any_row || r >= 0;
    }
    element_block_.push_back(kkt_.add_block(fi, fi));
    row_block_.push_back(any_row ? kkt_.add_block(cr, fi) : -1);
    column_block_.push_back(any_row ? kkt_.add_block(fi, cr) : -1);
  }
  for (int g = 0; g < sys.nx; ++g)
    point_block_.push_back(sys.point_mass[g] != 0.0 ? kkt_.add_block({layout.free_of[g]}, {layout.free_of[g]}) : -1);
  auto four = [&](int coord) {
    std::vector<int> fi(4);
    for (int i = 0; i < 4; ++i) fi[i] = layout.free_of[coord + i];
    return kkt_.add_block(fi, fi);
  };
  for (const BodyInertia& b : sys.bodies) body_block_.push_back(four(b.coord));
  for (const Torque& t : sys.torques) torque_block_.push_back(four(t.coord));
  kkt_.finalize();
  const Eigen::SparseMatrix<double>& A = kkt_.matrix();
  diagonal_.assign(nf, -1);
  for (int c = 0; c < nf; ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (it.row() == c) diagonal_[c] = static_cast<int>(&it.value() - A.valuePtr());
  rhs_ = sol_ = res_ = Eigen::VectorXd::Zero(n_);
  rest_.assign(rest_start_.back(), 0.0);
  for (std::vector<double>& part : parts_) part.assign(rest_start_.back(), 0.0);
  if (!symmetric_) {
    lu_.analyze(A);
    return;
  }
  // AMD's order, then each constraint row moved to just after the last of its coordinates, so
  // that no pivot is structurally zero (nodal.hpp).
  std::vector<int> order(n_);
  if (n_ > 0) {
    // The pattern is symmetric as registered (each element's block, its rows of A and their
    // transpose): AMD runs on it directly, without Eigen's A + Aᵀ (a sparse transpose and sum,
    // a quarter of the set-up's ordering).
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::SparseMatrix<double> pattern = A;
    Eigen::internal::minimum_degree_ordering(pattern, perm);
    for (int k = 0; k < n_; ++k) order[k] = perm.indices()[k];  // step → index
  }
  std::vector<double> key(n_);
  for (int k = 0; k < n_; ++k) key[order[k]] = k;
  for (int r = nf; r < n_; ++r) {
    double last = -1.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, r); it; ++it)
      if (it.row() < nf) last = std::max(last, key[it.row()]);
    key[r] = last + 0.5 + key[r] / (2.0 * n_);  // after its last coordinate, rows in AMD's order
  }
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  ldlt_.analyze(A, order);
}

void SaddlePoint::hold_part(const System& sys, const Data& data, const Eigen::VectorXd& sigma, int part,
                            double load_factor) {
  NodalCoefficients unit;  // the part's own coefficient 1, the others 0
  unit.stiffness = unit.damping = 0.0;
  unit.geometric = part == kGeometric ? 1.0 : 0.0;
  unit.mass = part == kMass ? 1.0 : 0.0;
  unit.load_factor = load_factor;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const int n = static_cast<int>(se.coords.size());
    if (part == kGeometric || part == kMass) {
      spacar::element_rest(sys, data, i, sigma, unit, local_);
    } else {
      local_.setZero(n, n);
      add_constitutive(sys, se, data.work[i].B, part == kStiffness ? se.S : se.D, 1.0, &layout_, local_);
    }
    std::copy(local_.data(), local_.data() + local_.size(), parts_[part].data() + rest_start_[i]);
  }
  held_[part] = true;
  if (part == kGeometric) held_load_factor_ = load_factor;
}

void SaddlePoint::assemble(const System& sys, Data& data, const Eigen::VectorXd& sigma, const NodalCoefficients& c,
                           bool same_state) {
  const Eigen::VectorXd& s = layout_.scale;
  const int nf = layout_.n_free;
  kkt_.set_zero();
  // The elements' H as the sum of their parts per unit coefficient, each evaluated once per state.
  if (!same_state) held_.fill(false);
  const double coefficient[kParts] = {c.geometric, c.mass, c.stiffness, c.damping};
  for (int p = 0; p < kParts; ++p)
    if (coefficient[p] != 0.0 && (!held_[p] || (p == kGeometric && held_load_factor_ != c.load_factor)))
      hold_part(sys, data, sigma, p, c.load_factor);
  // H, scaled to energies: H_s(a, b) = H(a, b) s_a s_b.
  auto scale_of = [&](int g) { return layout_.free_of[g] >= 0 ? s[layout_.free_of[g]] : 1.0; };
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const int n = static_cast<int>(se.coords.size());
    auto part = [&](int p) { return Eigen::Map<const Eigen::MatrixXd>(parts_[p].data() + rest_start_[i], n, n); };
    local_.setZero(n, n);
    for (int p : {kGeometric, kMass})
      if (coefficient[p] != 0.0) local_ += coefficient[p] * part(p);
    std::copy(local_.data(), local_.data() + local_.size(), rest_.data() + rest_start_[i]);
    for (int p : {kStiffness, kDamping})
      if (coefficient[p] != 0.0) local_ += coefficient[p] * part(p);
    const double* sc = element_scale_.data() + element_scale_start_[i];
    for (int b = 0; b < n; ++b)
      for (int a = 0; a < n; ++a) local_(a, b) *= sc[a] * sc[b];
    kkt_.add(element_block_[i], local_);
  }
  if (c.mass != 0.0) {
    for (int g = 0; g < sys.nx; ++g)
      if (point_block_[g] >= 0) kkt_.add_value(point_block_[g], 0, 0, c.mass * sys.point_mass[g] * scale_of(g) * scale_of(g));
    for (size_t b = 0; b < sys.bodies.size(); ++b)  // Euler parameters: unit scale
      kkt_.add(body_block_[b], c.mass * data.body_M[b]);
  }
  if (c.geometric != 0.0 && c.load_factor != 0.0)
    for (size_t t = 0; t < sys.torques.size(); ++t)
      kkt_.add(torque_block_[t], c.geometric * c.load_factor * sys.torques[t].stiffness());
  // The size of H for W: its largest diagonal entry (1 if H vanishes: a mechanism unloaded).
  double h = 0.0;
  const double* v = kkt_.matrix().valuePtr();
  for (int p : diagonal_)
    if (p >= 0) h = std::max(h, std::abs(v[p]));
  if (!(h > 0.0) || !std::isfinite(h)) h = 1.0;
  // A, each row scaled to the norm h: its multiplier then has a pivot of the size of H's (about
  // −h, where it would be −|a|²/h), and AᵀWA with W = 1/h adds h in the direction of each row.
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    if (row_block_[i] < 0) continue;
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    const int n = static_cast<int>(se.coords.size());
    const double* sc = element_scale_.data() + element_scale_start_[i];
    Eigen::MatrixXd& As = rows_;
    As.setZero(se.nd, n);
    local_.setZero(n, n);
    for (int a = 0; a < se.nd; ++a) {
      const int r = layout_.row_of[se.def_offset + a];
      if (r < 0) continue;
      for (int b = 0; b < n; ++b)
        if (layout_.free_of[se.coords[b]] >= 0) As(a, b) = B(a, b) * sc[b] / s[nf + r];
      const double norm = As.row(a).norm();
      if (!(norm > 0.0)) continue;
      As.row(a) *= h / norm;
      add_outer(As, a, &As(a, 0), As.outerStride(), 1.0 / h, local_);  // as in add_constitutive
    }
    kkt_.add(element_block_[i], local_);
    kkt_.add(row_block_[i], As);
    kkt_.add_transposed(column_block_[i], As);
  }
}

bool SaddlePoint::factorize(const System& sys, Data& data, const Eigen::VectorXd& sigma, const NodalCoefficients& c,
                            bool same_state) {
  assemble(sys, data, sigma, c, same_state);
  const Eigen::SparseMatrix<double>& A = kkt_.matrix();
  singular_ = false;
  negative_ = -1;
  double amax = 0.0;
  for (int p = 0; p < A.nonZeros(); ++p) amax = std::max(amax, std::abs(A.valuePtr()[p]));
  if (!std::isfinite(amax)) return false;
  const int m = layout_.n_rows;
  if (symmetric_) {
    if (!ldlt_.factorize(A, SparseLU::kSingular * amax)) return false;
    singular_ = ldlt_.perturbed() > 0;
    negative_ = ldlt_.negative() - m;
    sign_ = negative_ % 2 ? -1 : 1;
  } else {
    if (!lu_.factorize(A)) {
      singular_ = true;
      sign_ = 0;
      return true;
    }
    sign_ = lu_.sign_determinant() * (m % 2 ? -1 : 1);
  }
  return true;
}

void SaddlePoint::solve_scaled(Eigen::VectorXd& rhs, bool refine) {
  auto once = [&](const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    if (symmetric_) {
      x.resize(n_);
      ldlt_.solve(b.data(), x.data());
    } else {
      lu_.solve(b, x);
    }
  };
  once(rhs, sol_);
  if (!refine) {
    rhs = sol_;
    return;
  }
  // One step of iterative refinement: the factorization chose its pivots for no accuracy (the
  // error left is that of the assembled matrix itself, which ReducedSystem refines away).
  res_ = rhs;
  res_.noalias() -= kkt_.matrix() * sol_;
  Eigen::VectorXd correction;
  once(res_, correction);
  sol_ += correction;
  rhs = sol_;
}

void SaddlePoint::solve_free(const double* r, double* dx, bool refine) {
  const Eigen::VectorXd& s = layout_.scale;
  const int nf = layout_.n_free;
  for (int f = 0; f < nf; ++f) rhs_[f] = r[f] * s[f];
  rhs_.tail(layout_.n_rows).setZero();
  solve_scaled(rhs_, refine);
  for (int f = 0; f < nf; ++f) dx[f] = rhs_[f] * s[f];
}

void SaddlePoint::solve(const Eigen::VectorXd& r, Eigen::VectorXd& dx, bool refine) {
  const int nf = layout_.n_free;
  Eigen::VectorXd rf(nf), xf(nf);
  for (int f = 0; f < nf; ++f) rf[f] = r[layout_.free[f]];
  solve_free(rf.data(), xf.data(), refine);
  dx = Eigen::VectorXd::Zero(r.size());
  for (int f = 0; f < nf; ++f) dx[layout_.free[f]] = xf[f];
}

Eigen::VectorXd SaddlePoint::null_direction() {
  if (!singular_ || !symmetric_) return {};
  double value = 0.0;
  return lowest_direction(3, value);
}

Eigen::VectorXd SaddlePoint::lowest_direction(int iterations, double& value) {
  const int nf = layout_.n_free;
  // Inverse iteration in the scaled coordinates from a start with every component.
  Eigen::VectorXd u(n_);
  for (int i = 0; i < n_; ++i) u[i] = i < nf ? 1.0 + 0.1 * std::sin(1.0 + i) : 0.0;
  for (int it = 0; it < iterations; ++it) {
    u.tail(layout_.n_rows).setZero();
    const double norm = u.head(nf).norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) break;
    u /= norm;
    rhs_ = u;
    solve_scaled(rhs_, true);
    value = u.head(nf).dot(rhs_.head(nf));  // uᵀ H⁻¹ u on the constrained space: 1 / μ
    value = value != 0.0 ? 1.0 / value : 0.0;
    u = rhs_;
  }
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(static_cast<int>(layout_.free_of.size()));
  for (int f = 0; f < nf; ++f) dx[layout_.free[f]] = u[f] * layout_.scale[f];
  return dx;
}

ReducedSystem::ReducedSystem(const System& sys, Data& data)
    : sys_(sys), data_(data), layout_(sys), saddle_(sys, layout_) {
  dof_of_def_.assign(sys.ne, -1);
  const int nxd = static_cast<int>(sys.x_dyn.size());
  for (size_t j = 0; j < sys.e_dyn.size(); ++j) dof_of_def_[sys.e_dyn[j]] = nxd + static_cast<int>(j);
}

bool ReducedSystem::factorize(const Eigen::VectorXd& sigma, const NodalCoefficients& c, bool same_state) {
  c_ = c;
  return saddle_.factorize(sys_, data_, sigma, c, same_state);
}

Eigen::VectorXd ReducedSystem::load(const Eigen::VectorXd& v) const {
  // Unit loads on DOF coordinates, B_kᵀ v_k on the coordinates of a DOF deformation k.
  const int nxd = static_cast<int>(sys_.x_dyn.size());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(sys_.nx);
  for (int j = 0; j < nxd; ++j) b[sys_.x_dyn[j]] += v[j];
  for (size_t j = 0; j < sys_.e_dyn.size(); ++j) {
    const int k = sys_.e_dyn[j], i = sys_.e_element[k];
    const SystemElement& se = sys_.elements[i];
    for (size_t c = 0; c < se.coords.size(); ++c) b[se.coords[c]] += data_.work[i].B(k - se.def_offset, c) * v[nxd + j];
  }
  return b;
}

Eigen::VectorXd ReducedSystem::dofs(const Eigen::VectorXd& dx) const {
  const int nxd = static_cast<int>(sys_.x_dyn.size());
  Eigen::VectorXd q(sys_.n_dof());
  for (int j = 0; j < nxd; ++j) q[j] = dx[sys_.x_dyn[j]];
  for (size_t j = 0; j < sys_.e_dyn.size(); ++j) {
    const int k = sys_.e_dyn[j], i = sys_.e_element[k];
    const SystemElement& se = sys_.elements[i];
    double v = 0.0;
    for (size_t c = 0; c < se.coords.size(); ++c) v += data_.work[i].B(k - se.def_offset, c) * dx[se.coords[c]];
    q[nxd + j] = v;
  }
  return q;
}

Eigen::VectorXd ReducedSystem::reduce(const Eigen::VectorXd& b) {
  Eigen::VectorXd out;
  transfer_transposed(sys_, data_, b, out);
  Eigen::VectorXd v(sys_.n_dof());
  for (int j = 0; j < sys_.n_dof(); ++j) v[j] = out[sys_.dof_cols[j]];
  return v;
}

Eigen::VectorXd ReducedSystem::motion(const Eigen::VectorXd& q) {
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(sys_.n_qhat()), dx;
  for (int j = 0; j < sys_.n_dof(); ++j) rate[sys_.dof_cols[j]] = q[j];
  transfer_times(sys_, data_, rate, dx);
  return dx;
}

Eigen::VectorXd ReducedSystem::product(const Eigen::VectorXd& q, Eigen::VectorXd* dx_out) {
  const Eigen::VectorXd dx = motion(q);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(sys_.n_dof());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sys_.nx), xe, de;
  for (size_t i = 0; i < sys_.elements.size(); ++i) {
    const SystemElement& se = sys_.elements[i];
    const Eigen::MatrixXd& B = data_.work[i].B;
    const int n = static_cast<int>(se.coords.size());
    xe.resize(n);
    for (int j = 0; j < n; ++j) xe[j] = dx[se.coords[j]];
    // The rest of H (geometric, loads', mass) element by element; its terms do not cancel.
    const Eigen::VectorXd fe = saddle_.element_rest(i, n) * xe;
    for (int j = 0; j < n; ++j) f[se.coords[j]] += fe[j];
    if (!se.has_constitutive || (c_.stiffness == 0.0 && c_.damping == 0.0)) continue;
    // The deformations' increments, those of DOF deformations exactly; their stresses, of a
    // DOF deformation straight into y (Zᵀ B_kᵀ is the unit row of its DOF), of the others
    // through the coordinates.
    de.noalias() = B * xe;
    for (int a = 0; a < se.nd; ++a)
      if (dof_of_def_[se.def_offset + a] >= 0) de[a] = q[dof_of_def_[se.def_offset + a]];
    for (int a = 0; a < se.nd; ++a) {
      const int k = se.def_offset + a;
      if (!constitutive_class(sys_.def_class[k])) continue;
      const double stress = c_.stiffness * se.S.row(a).dot(de) + c_.damping * se.D.row(a).dot(de);
      if (dof_of_def_[k] >= 0) y[dof_of_def_[k]] += stress;
      else
        for (int j = 0; j < n; ++j) f[se.coords[j]] += B(a, j) * stress;
    }
  }
  if (c_.mass != 0.0) {
    for (int g = 0; g < sys_.nx; ++g) f[g] += c_.mass * sys_.point_mass[g] * dx[g];
    for (size_t b = 0; b < sys_.bodies.size(); ++b)
      f.segment<4>(sys_.bodies[b].coord) += c_.mass * data_.body_M[b] * dx.segment<4>(sys_.bodies[b].coord);
  }
  if (c_.geometric != 0.0 && c_.load_factor != 0.0)
    for (const Torque& t : sys_.torques)
      f.segment<4>(t.coord) += c_.geometric * c_.load_factor * t.stiffness() * dx.segment<4>(t.coord);
  y += reduce(f);
  if (dx_out) *dx_out = dx;
  return y;
}

void ReducedSystem::solve_mass(const Eigen::VectorXd& v, Eigen::VectorXd& q, Eigen::VectorXd& dx) {
  // The nodal load M Z v, not load(Zᵀ M Z v): the saddle point's solution depends on its load b
  // only through Zᵀ b (the constraints' forces take the rest), which saves a transposed solve.
  Eigen::VectorXd f;
  inertia_times(sys_, data_, motion(v), f);
  saddle_.solve(f, dx, false);
  q = dofs(dx);
}

void ReducedSystem::solve(const Eigen::VectorXd& r, Eigen::VectorXd& q, Eigen::VectorXd& dx, int refinements) {
  saddle_.solve(load(r), dx, refinements > 0);
  q = dofs(dx);
  if (refinements <= 0) return;
  Eigen::VectorXd step;
  const double size = r.cwiseAbs().maxCoeff();
  for (int it = 0; it < refinements && size > 0.0; ++it) {
    const Eigen::VectorXd residual = r - product(q);
    if (!(residual.cwiseAbs().maxCoeff() > 1e-15 * size)) break;
    saddle_.solve(load(residual), step);
    const Eigen::VectorXd dq = dofs(step);
    q += dq;
    if (!(dq.cwiseAbs().maxCoeff() > 1e-15 * q.cwiseAbs().maxCoeff())) break;
  }
  dx = motion(q);
}

}  // namespace spacar
