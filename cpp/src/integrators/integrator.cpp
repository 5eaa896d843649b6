// Embedded Runge-Kutta integrators DOP853 and DOPRI5 (see integrator.hpp). The coefficients are the
// published ones of Hairer, Norsett & Wanner (DOP853, dense output of order 7) and of Dormand &
// Prince with Hairer's dense output (DOPRI5). Step control follows Hairer's codes: the solution is
// advanced with the high-order formula, the step adapts as h * 0.9 * err^(-1/q) within limits.
#include "spacar/integrators/integrator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "spacar/errors.hpp"

namespace spacar {

namespace {

using Row = std::array<double, 16>;

// A method's tableau. Stages 0..s-1 make the step; the solution uses the weights of row s, and
// stage s is f(t + h, y_new), which becomes stage 0 of the next step (first same as last). Stages
// s+1 .. total-1 are needed only by the dense output.
struct Scheme {
  int s;
  int total;
  int dense_rows;     // rows of d: coefficients of the dense polynomial beyond its Hermite part
  double q;           // order that sets the controller exponent -1/q and the initial-step formula
  double fac_min, fac_max;
  bool error_needs_last_stage;   // the error estimate uses f(t + h, y_new)
  double stiff_bound;            // h|λ| beyond which a step counts as stiff (Hairer's codes)
  const double* c;
  const Row* a;
  const Row* d;
};

// --- DOP853 -------------------------------------------------------------------------------------

constexpr double kC853[16] = {
    0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510, 0.281649658092772603273242802490,
    0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692,
    0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0, 1.0, 0.1, 0.2,
    0.777777777777777777777777777778};

constexpr Row kA853[16] = {
    Row{},
    Row{5.26001519587677318785587544488e-2},
    Row{1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2},
    Row{2.95875854768068491816892993775e-2, 0, 8.87627564304205475450678981324e-2},
    Row{2.41365134159266685502369798665e-1, 0, -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1},
    Row{3.7037037037037037037037037037e-2, 0, 0, 1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1},
    Row{3.7109375e-2, 0, 0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2,
        -1.7578125e-2},
    Row{3.70920001185047927108779319836e-2, 0, 0, 1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3},
    Row{6.24110958716075717114429577812e-1, 0, 0, -3.36089262944694129406857109825,
        -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1},
    Row{4.77662536438264365890433908527e-1, 0, 0, -2.48811461997166764192642586468,
        -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2},
    Row{-9.3714243008598732571704021658e-1, 0, 0, 5.18637242884406370830023853209,
        1.09143734899672957818500254654, -8.14978701074692612513997267357,
        -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1,
        2.49360555267965238987089396762, -3.0467644718982195003823669022},
    Row{2.27331014751653820792359768449, 0, 0, -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444, -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1, -2.85899827713502369474065508674,
        -8.87285693353062954433549289258, 1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1},
    // Row 12: the weights b of the 8th-order solution.
    Row{5.42937341165687622380535766363e-2, 0, 0, 0, 0, 4.45031289275240888144113950566,
        1.89151789931450038304281599044, -5.8012039600105847814672114227,
        3.1116436695781989440891606237e-1, -1.52160949662516078556178806805e-1,
        2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2},
    // Rows 13-15: the three extra stages of the 7th-order dense output.
    Row{5.61675022830479523392909219681e-2, 0, 0, 0, 0, 0, 2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1, -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1, 8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3, -8.298e-3},
    Row{3.18346481635021405060768473261e-2, 0, 0, 0, 0, 2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2, -5.49237485713909884646569340306e-2, 0, 0,
        -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4, 1.41312443674632500278074618366e-1},
    Row{-4.28896301583791923408573538692e-1, 0, 0, 0, 0, -4.69762141536116384314449447206,
        7.68342119606259904184240953878, 4.06898981839711007970213554331,
        3.56727187455281109270669543021e-1, 0, 0, 0, -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149, -9.15095847217987001081870187138},
};

// Difference between the 8th-order solution and the embedded 5th-order one (per unit step).
constexpr Row kE5_853 = {0.1312004499419488073250102996e-1, 0, 0, 0, 0,
                         -0.1225156446376204440720569753e+1, -0.4957589496572501915214079952,
                         0.1664377182454986536961530415e+1, -0.3503288487499736816886487290,
                         0.3341791187130174790297318841, 0.8192320648511571246570742613e-1,
                         -0.2235530786388629525884427845e-1};

// Difference between the 8th-order solution and the embedded 3rd-order one: b minus the weights
// bhh of the 3rd-order formula, which has only three non-zero weights.
constexpr Row make_e3_853() {
  Row e = kA853[12];
  e[0] -= 0.244094488188976377952755905512;
  e[8] -= 0.733846688281611857341361741547;
  e[11] -= 0.220588235294117647058823529412e-1;
  return e;
}
constexpr Row kE3_853 = make_e3_853();

// Coefficients of the 7th-order dense output beyond the Hermite part (multiplied by h).
constexpr Row kD853[4] = {
    Row{-0.84289382761090128651353491142e+1, 0, 0, 0, 0, 0.56671495351937776962531783590,
        -0.30689499459498916912797304727e+1, 0.23846676565120698287728149680e+1,
        0.21170345824450282767155149946e+1, -0.87139158377797299206789907490,
        0.22404374302607882758541771650e+1, 0.63157877876946881815570249290,
        -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e+2,
        -0.91946323924783554000451984436e+1, -0.44360363875948939664310572000e+1},
    Row{0.10427508642579134603413151009e+2, 0, 0, 0, 0, 0.24228349177525818288430175319e+3,
        0.16520045171727028198505394887e+3, -0.37454675472269020279518312152e+3,
        -0.22113666853125306036270938578e+2, 0.77334326684722638389603898808e+1,
        -0.30674084731089398182061213626e+2, -0.93321305264302278729567221706e+1,
        0.15697238121770843886131091075e+2, -0.31139403219565177677282850411e+2,
        -0.93529243588444783865713862664e+1, 0.35816841486394083752465898540e+2},
    Row{0.19985053242002433820987653617e+2, 0, 0, 0, 0, -0.38703730874935176555105901742e+3,
        -0.18917813819516756882830838328e+3, 0.52780815920542364900561016686e+3,
        -0.11573902539959630126141871134e+2, 0.68812326946963000169666922661e+1,
        -0.10006050966910838403183860980e+1, 0.77771377980534432092869265740,
        -0.27782057523535084065932004339e+1, -0.60196695231264120758267380846e+2,
        0.84320405506677161018159903784e+2, 0.11992291136182789328035130030e+2},
    Row{-0.25693933462703749003312586129e+2, 0, 0, 0, 0, -0.15418974869023643374053993627e+3,
        -0.23152937917604549567536039109e+3, 0.35763911791061412378285349910e+3,
        0.93405324183624310003907691704e+2, -0.37458323136451633156875139351e+2,
        0.10409964950896230045147246184e+3, 0.29840293426660503123344363579e+2,
        -0.43533456590011143754432175058e+2, 0.96324553959188282948394950600e+2,
        -0.39177261675615439165231486172e+2, -0.14972683625798562581422125276e+3},
};

// --- DOPRI5 -------------------------------------------------------------------------------------

constexpr double kC5[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};

constexpr Row kA5[7] = {
    Row{},
    Row{1.0 / 5},
    Row{3.0 / 40, 9.0 / 40},
    Row{44.0 / 45, -56.0 / 15, 32.0 / 9},
    Row{19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    Row{9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    // Row 6: the weights b of the 5th-order solution.
    Row{35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84},
};

// Difference between the 5th-order solution and the embedded 4th-order one.
constexpr Row kE5_dopri = {71.0 / 57600,  0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200,
                           22.0 / 525, -1.0 / 40};

// Coefficients of the 4th-order dense output beyond the Hermite part (Hairer's DOPRI5).
constexpr Row kD5[1] = {Row{-12715105075.0 / 11282082432, 0, 87487479700.0 / 32700410799,
                            -10690763975.0 / 1880347072, 701980252875.0 / 199316789632,
                            -1453857185.0 / 822651844, 69997945.0 / 29380423}};

constexpr Scheme kDop853{12, 16, 4, 8.0, 0.333, 6.0, false, 6.1, kC853, kA853, kD853};
constexpr Scheme kDopri5{6, 7, 1, 5.0, 0.2, 10.0, true, 3.25, kC5, kA5, kD5};

const Scheme& scheme(Method m) { return m == Method::DOP853 ? kDop853 : kDopri5; }


// out = y + h * sum_j row[j] * k[j] over the first `count` stages (zero weights skipped: the
// tableaux are sparse).
void combine(const Eigen::VectorXd& y, double h, const Row& row, int count,
             const std::vector<Eigen::VectorXd>& k, Eigen::VectorXd& out) {
  out = y;
  for (int j = 0; j < count; ++j)
    if (row[j] != 0.0) out += (h * row[j]) * k[j];
}

// out = sum_j row[j] * k[j] over the first `count` stages.
void weighted_sum(const Row& row, int count, const std::vector<Eigen::VectorXd>& k,
                  Eigen::VectorXd& out) {
  out.setZero();
  for (int j = 0; j < count; ++j)
    if (row[j] != 0.0) out += row[j] * k[j];
}

}  // namespace

Integrator::Integrator(int n, Method method) : Stepper("Integrator", n), method_(method) {
  if (n < 1) throw std::invalid_argument("Integrator: the system needs at least one state");
  if (method != Method::DOP853 && method != Method::DOPRI5)
    throw std::invalid_argument("Integrator: only DOP853 and DOPRI5 (RADAU5 is the class Radau5)");
  const Scheme& sc = scheme(method);
  k_.assign(sc.total, Eigen::VectorXd::Zero(n));
  dense_.assign(3 + sc.dense_rows, Eigen::VectorXd::Zero(n));
  for (Eigen::VectorXd* v : {&y_stage_, &y_new_, &scale_, &err_a_, &err_b_, &y_out_})
    v->setZero(n);
}

std::unique_ptr<Stepper> Integrator::make(Method method, const StepperSetup& setup) {
  auto stepper = std::make_unique<Integrator>(setup.n, method);
  stepper->set_stiffness_detection(setup.auto_switch, setup.stiff_steps_ahead, setup.stiff_bound, setup.stiff_count);
  return stepper;
}

void Integrator::set_stiffness_detection(bool on, double min_steps_ahead, double bound, int count) {
  if (!(min_steps_ahead >= 0)) throw std::invalid_argument("Integrator: min_steps_ahead must be >= 0");
  if (!(bound >= 0)) throw std::invalid_argument("Integrator: the stiffness bound must be >= 0");
  if (count < 1) throw std::invalid_argument("Integrator: the count of stiff steps must be >= 1");
  detect_stiffness_ = on;
  stiff_count_ = count;
  min_steps_ahead_ = min_steps_ahead;
  stiff_bound_ = bound > 0.0 ? bound : scheme(method_).stiff_bound;
}
double Integrator::stiffness_estimate() const { return hlamb_; }
double Integrator::stiffness_bound(Method m) {
  if (m != Method::DOP853 && m != Method::DOPRI5)
    throw std::invalid_argument("Integrator: stiffness bounds are those of DOP853 and DOPRI5");
  return scheme(m).stiff_bound;
}

// h|λ| from the two evaluations at t + h of the step just computed: k_[s] = f(t + h, y_new) and
// k_[s-1] = f(t + h, Y) with Y = y_stage_, the argument of the last stage (c = 1 in both schemes).
void Integrator::estimate_stiffness(double h) {
  const Scheme& sc = scheme(method_);
  const double num = (k_[sc.s] - k_[sc.s - 1]).squaredNorm();
  const double den = (y_new_ - y_stage_).squaredNorm();
  hlamb_ = den > 0.0 ? std::abs(h) * std::sqrt(num / den) : 0.0;
}

// Hairer's counting after an accepted step: true once stiff_count_ (his 15) steps were stiff with
// no run of kNonstiffSteps non-stiff ones between them.
bool Integrator::stiff_after_step() {
  if (hlamb_ > stiff_bound_) {
    nonstiff_steps_ = 0;
    return ++stiff_steps_ >= stiff_count_;
  }
  if (++nonstiff_steps_ >= kNonstiffSteps) stiff_steps_ = 0;
  return false;
}

// Stages first..last-1 of a step of size h from (t, y).
bool Integrator::eval_stages(const Rhs& f, double t, double h, const Eigen::VectorXd& y, int first,
                             int last) {
  const Scheme& sc = scheme(method_);
  for (int i = first; i < last; ++i) {
    combine(y, h, sc.a[i], i, k_, y_stage_);
    if (!eval(f, t + sc.c[i] * h, y_stage_, k_[i])) return false;
  }
  return true;
}

// Hairer's starting step: make the explicit Euler step's error about 0.01 in the scaled norm and
// its second derivative term acceptable for a method of order q. Uses k_[0] = f(t0, y).
double Integrator::initial_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) {
  const Scheme& sc = scheme(method_);
  const double span = std::min(hmax_, t_end - t0);
  const double rms = 1.0 / std::sqrt(static_cast<double>(n_));
  scale_ = atol_.array() + rtol_.array() * y.array().abs();
  // Components at round-off (an assembly's 1e-17 for an exact zero) count as zero: against a
  // tight absolute tolerance they would make d0 pass Hairer's 1e-5 test and 0.01 d0/d1, which
  // also caps the step below at 100 times itself, spuriously tiny (1e-18 s).
  const double noise = 1e-14 * std::max(1.0, y.cwiseAbs().maxCoeff());
  const double d0 = ((y.array().abs() > noise).select(y.array(), 0.0) / scale_.array()).matrix().norm() * rms;
  const double d1 = (k_[0].array() / scale_.array()).matrix().norm() * rms;
  const double h0 = std::min((d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1, span);

  // Probe the rhs one Euler step ahead; if it fails there, start with h0 and let the step loop
  // shrink it.
  y_stage_ = y + h0 * k_[0];
  try {
    if (!eval(f, t0 + h0, y_stage_, k_[1])) return h0;
  } catch (const StepRejected&) {
    return h0;
  }
  const double d2 = ((k_[1] - k_[0]).array() / scale_.array()).matrix().norm() * rms / h0;
  const double dmax = std::max(d1, d2);
  const double h1 = dmax <= 1e-15 ? std::max(1e-6, 1e-3 * h0) : std::pow(0.01 / dmax, 1.0 / sc.q);
  return std::min({100.0 * h0, h1, span});
}

// Scaled RMS error of the step just computed (y_new_ from y); the scale uses the larger of the old
// and new magnitudes so that a component passing through zero is not over-resolved.
double Integrator::error_norm(double h) {
  const Scheme& sc = scheme(method_);
  if (method_ == Method::DOPRI5) {
    weighted_sum(kE5_dopri, sc.s + 1, k_, err_a_);
    return std::abs(h) * (err_a_.array() / scale_.array()).matrix().norm() /
           std::sqrt(static_cast<double>(n_));
  }
  // DOP853 combines the 5th-order estimate err5 with the 3rd-order one err3 as
  // err5^2 / sqrt(err5^2 + 0.01 err3^2): for small h this scales like h^8, the local error of the
  // 7th-order embedded solution (hence the exponent 1/8), for large h it tends to err5 itself.
  weighted_sum(kE5_853, sc.s, k_, err_a_);
  weighted_sum(kE3_853, sc.s, k_, err_b_);
  const double e5 = (err_a_.array() / scale_.array()).square().sum();
  const double e3 = (err_b_.array() / scale_.array()).square().sum();
  const double denom = e5 + 0.01 * e3;
  if (denom <= 0.0) return 0.0;
  return std::abs(h) * e5 / std::sqrt(n_ * denom);
}

// One trial step of size h from (t, y) to t_new; with `dense`, also the dense-output polynomial,
// computed before acceptance so that a failing extra stage rejects the step instead of losing it.
Integrator::Attempt Integrator::attempt_step(const Rhs& f, double t, double h, double t_new,
                                             const Eigen::VectorXd& y, bool dense) {
  const Scheme& sc = scheme(method_);
  if (!eval_stages(f, t, h, y, 1, sc.s)) return Attempt::Failed;
  combine(y, h, sc.a[sc.s], sc.s, k_, y_new_);
  if (sc.error_needs_last_stage && !eval(f, t_new, y_new_, k_[sc.s])) return Attempt::Failed;

  scale_ = atol_.array() + rtol_.array() * y.array().abs().max(y_new_.array().abs());
  err_ = error_norm(h);
  if (!std::isfinite(err_)) {
    failure_ = "non-finite error estimate";
    return Attempt::Failed;
  }
  if (err_ > 1.0) {
    failure_ = "local error above tolerance";
    return Attempt::ErrorTooLarge;
  }
  // DOP853 needs f(t_new, y_new) only once the step is accepted (it starts the next step).
  if (!sc.error_needs_last_stage && !eval(f, t_new, y_new_, k_[sc.s])) return Attempt::Failed;
  if (detect_stiffness_) estimate_stiffness(h);   // before the dense stages overwrite y_stage_
  if (dense && !build_dense(f, t, h, y)) return Attempt::Failed;
  return Attempt::Accepted;
}

// Step-size ratio the last error norm asks for, before the limits: the error scales as h^q.
double Integrator::step_factor() const {
  const Scheme& sc = scheme(method_);
  return err_ == 0.0 ? sc.fac_max : kStepSafety * std::pow(err_, -1.0 / sc.q);
}

// Coefficients F of y(t + theta h) = y + theta (F0 + (1-theta) (F1 + theta (F2 + (1-theta) (F3
// + ...)))): F0..F2 make the cubic Hermite interpolant of the step ends, the rest come from the
// stages.
bool Integrator::build_dense(const Rhs& f, double t, double h, const Eigen::VectorXd& y) {
  const Scheme& sc = scheme(method_);
  if (!eval_stages(f, t, h, y, sc.s + 1, sc.total)) return false;
  dense_[0] = y_new_ - y;
  dense_[1] = h * k_[0] - dense_[0];
  dense_[2] = dense_[0] - h * k_[sc.s] - dense_[1];
  for (int r = 0; r < sc.dense_rows; ++r) {
    weighted_sum(sc.d[r], sc.total, k_, dense_[3 + r]);
    dense_[3 + r] *= h;
  }
  return true;
}

// y_out_ = dense output at fraction theta of the accepted step that started at y_old.
void Integrator::dense_value(double theta, const Eigen::VectorXd& y_old) {
  const int m = static_cast<int>(dense_.size());
  y_out_ = dense_[m - 1];
  for (int i = m - 2; i >= 0; --i)
    y_out_ = dense_[i] + ((i % 2 == 0) ? 1.0 - theta : theta) * y_out_;
  y_out_ = y_old + theta * y_out_;
}

// Calls out for the output times in (t, t_new] of the step just accepted (y_new_ from y, not yet
// committed); returns the index of the first output time after the step.
size_t Integrator::emit_outputs(const std::vector<double>& touts, size_t next, double t, double h,
                                double t_new, const Eigen::VectorXd& y, const Output& out) {
  for (; next < touts.size() && touts[next] <= t_new; ++next) {
    if (touts[next] == t_new) {
      out(t_new, y_new_);   // exactly the step end, not the interpolant evaluated there
    } else {
      dense_value((touts[next] - t) / h, y);
      out(touts[next], y_out_);
    }
  }
  return next;
}

void Integrator::begin() {
  hlamb_ = 0.0;
  stiff_steps_ = nonstiff_steps_ = 0;
  rejected_ = false;
}

bool Integrator::start(const Rhs& f, double t0, const Eigen::VectorXd& y) { return eval(f, t0, y, k_[0]); }

double Integrator::first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) {
  return std::min(h_initial_ > 0 ? h_initial_ : initial_step(f, t0, t_end, y), hmax_);
}

Stepper::Outcome Integrator::step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y,
                                  Outputs& outputs, double& h) {
  const Scheme& sc = scheme(method_);
  const bool dense = outputs.next < outputs.touts.size() && outputs.touts[outputs.next] < t_new;
  Attempt result = Attempt::Failed;
  try {
    result = attempt_step(f, t, h_try, t_new, y, dense);
  } catch (const StepRejected& e) {
    failure_ = e.what();
  }
  if (result != Attempt::Accepted) {
    h = h_try * (result == Attempt::Failed ? 0.5 : std::max(sc.fac_min, step_factor()));
    rejected_ = true;
    return Outcome::Rejected;
  }
  outputs.next = emit_outputs(outputs.touts, outputs.next, t, h_try, t_new, y, outputs.out);
  double grow = std::clamp(step_factor(), sc.fac_min, sc.fac_max);
  if (rejected_) grow = std::min(grow, 1.0);
  h = std::min(h_try * grow, hmax_);
  y = y_new_;
  std::swap(k_[0], k_[sc.s]);
  rejected_ = false;
  return Outcome::Accepted;
}

bool Integrator::switch_after_step(double t, double t_end, double h) {
  return detect_stiffness_ && stiff_after_step() && t_end - t > min_steps_ahead_ * h;
}

}  // namespace spacar
