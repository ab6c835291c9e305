// Dierckx's smoothing-spline algorithm (see curfit.hpp). The indices are
// 1-based, as in the book, so that every step can be checked against it.
#include "device_gen/fitpack/curfit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stentsim::device_gen::fitpack {
namespace {

/// 1-based vector and matrix views over std::vector storage.
struct Vec1 {
  std::vector<double> v;
  explicit Vec1(std::size_t n) : v(n + 1, 0.0) {}
  double& operator()(int i) { return v[static_cast<std::size_t>(i)]; }
};
struct IVec1 {
  std::vector<int> v;
  explicit IVec1(std::size_t n) : v(n + 1, 0) {}
  int& operator()(int i) { return v[static_cast<std::size_t>(i)]; }
};
struct Mat1 {
  std::size_t cols;
  std::vector<double> v;
  Mat1(std::size_t rows, std::size_t c) : cols(c), v((rows + 1) * (c + 1), 0.0) {}
  double& operator()(int i, int j) { return v[static_cast<std::size_t>(i) * (cols + 1) + static_cast<std::size_t>(j)]; }
};

/// Givens rotation that annihilates piv against the diagonal ww (Dierckx 4.1.2).
void givens(double piv, double& ww, double& cos, double& sin) {
  const double store = std::abs(piv);
  const double dd = store >= ww ? store * std::sqrt(1.0 + (ww / piv) * (ww / piv))
                                : ww * std::sqrt(1.0 + (piv / ww) * (piv / ww));
  cos = ww / dd;
  sin = piv / dd;
  ww = dd;
}

void rotate(double cos, double sin, double& a, double& b) {
  const double s1 = a, s2 = b;
  b = cos * s2 + sin * s1;
  a = cos * s1 - sin * s2;
}

/// Back substitution for an upper triangular band matrix of bandwidth k.
void back_substitute(Mat1& a, Vec1& z, int n, int k, Vec1& c) {
  const int k1 = k - 1;
  c(n) = z(n) / a(n, 1);
  int i = n - 1;
  if (i == 0) return;
  for (int j = 2; j <= n; ++j) {
    double store = z(i);
    const int i1 = j <= k1 ? j - 1 : k1;
    int m = i;
    for (int l = 1; l <= i1; ++l) {
      ++m;
      store -= c(m) * a(i, l + 1);
    }
    c(i) = store / a(i, 1);
    --i;
  }
}

/// The k+1 non-zero B-splines at x in the 1-based span l (Cox-de Boor).
void basis1(Vec1& t, int k, double x, int l, double* h) {
  double hh[8];
  h[1] = 1.0;
  for (int j = 1; j <= k; ++j) {
    for (int i = 1; i <= j; ++i) hh[i] = h[i];
    h[1] = 0.0;
    for (int i = 1; i <= j; ++i) {
      const int li = l + i, lj = li - j;
      const double f = hh[i] / (t(li) - t(lj));
      h[i] += f * (t(li) - x);
      h[i + 1] = f * (x - t(lj));
    }
  }
}

/// Jumps of the k-th derivative of the B-splines at the interior knots,
/// scaled by ((n-2k-1)/(xe-xb))^k for conditioning (Dierckx 5.2.2).
void derivative_jumps(Vec1& t, int n, int k2, Mat1& b) {
  const int k1 = k2 - 1, k = k1 - 1, nk1 = n - k1, nrint = nk1 - k;
  const double fac = static_cast<double>(nrint) / (t(nk1 + 1) - t(k1));
  double h[16];
  for (int l = k2; l <= nk1; ++l) {
    const int lmk = l - k1;
    for (int j = 1; j <= k1; ++j) {
      h[j] = t(l) - t(l + j - k2);
      h[j + k1] = t(l) - t(l + j);
    }
    int lp = lmk;
    for (int j = 1; j <= k2; ++j) {
      int jk = j;
      double prod = h[j];
      for (int i = 1; i <= k; ++i) {
        ++jk;
        prod = prod * h[jk] * fac;
      }
      b(lmk, j) = (t(lp + k1) - t(lp)) / prod;
      ++lp;
    }
  }
}

/// Adds one knot at the middle data point of the interval with the largest
/// residual share (Dierckx 5.3.2); keeps the per-interval bookkeeping.
void add_knot(Vec1& x, Vec1& t, int& n, Vec1& fpint, IVec1& nrdata, int& nrint, int istart) {
  const int k = (n - nrint - 1) / 2;
  double fpmax = 0.0;
  int number = 0, maxpt = 0, maxbeg = 0;
  int jbegin = istart;
  for (int j = 1; j <= nrint; ++j) {
    const int jpoint = nrdata(j);
    if (!(fpmax >= fpint(j) || jpoint == 0)) {
      fpmax = fpint(j);
      number = j;
      maxpt = jpoint;
      maxbeg = jbegin;
    }
    jbegin += jpoint + 1;
  }
  if (number == 0) throw std::runtime_error("smoothing spline: no knot interval with data points left to split");
  const int ihalf = maxpt / 2 + 1;
  const int nrx = maxbeg + ihalf;
  const int next = number + 1;
  for (int j = next; j <= nrint; ++j) {
    const int jj = next + nrint - j;
    fpint(jj + 1) = fpint(jj);
    nrdata(jj + 1) = nrdata(jj);
    t(jj + k + 1) = t(jj + k);
  }
  nrdata(number) = ihalf - 1;
  nrdata(next) = maxpt - ihalf;
  const double am = maxpt;
  fpint(number) = fpmax * nrdata(number) / am;
  fpint(next) = fpmax * nrdata(next) / am;
  t(next + k) = x(nrx);
  ++n;
  ++nrint;
}

/// Root of the rational interpolant r(p) = (u p + v)/(p + w) through three
/// points of f(p) - s (Dierckx 5.2.4); p3 < 0 means p3 = infinity. Updates
/// the bracket so that f1 > 0 > f3.
double rational_root(double& p1, double& f1, double p2, double f2, double& p3, double& f3) {
  double p;
  if (p3 > 0.0) {
    const double h1 = f1 * (f2 - f3), h2 = f2 * (f3 - f1), h3 = f3 * (f1 - f2);
    p = -(p1 * p2 * h3 + p2 * p3 * h1 + p3 * p1 * h2) / (p1 * h1 + p2 * h2 + p3 * h3);
  } else {
    p = (p1 * (f1 - f3) * f2 - p2 * (f2 - f3) * f1) / ((f1 - f2) * f3);
  }
  if (f2 < 0.0) {
    p3 = p2;
    f3 = f2;
  } else {
    p1 = p2;
    f1 = f2;
  }
  return p;
}

/// State of one fit that survives between a call and its continuation
/// (FITPACK's t, n, c, fpint, nrdata arrays with iopt = 1).
struct Workspace {
  int m, k, k1, k2, nmax_storage;
  Vec1 x, y, w, t, c, fpint, z;
  IVec1 nrdata;
  Mat1 a, b, g, q;
  int n = 0;
  double fp = 0, fp0 = 0, p = std::numeric_limits<double>::infinity();

  Workspace(const std::vector<double>& xs, const std::vector<double>& ys, const std::vector<double>& ws, int deg)
      : m(static_cast<int>(xs.size())), k(deg), k1(deg + 1), k2(deg + 2), nmax_storage(m + deg + 1),
        x(xs.size()), y(xs.size()), w(xs.size()), t(static_cast<std::size_t>(nmax_storage)),
        c(static_cast<std::size_t>(nmax_storage)), fpint(static_cast<std::size_t>(nmax_storage)),
        z(static_cast<std::size_t>(nmax_storage)), nrdata(static_cast<std::size_t>(nmax_storage)),
        a(static_cast<std::size_t>(nmax_storage), static_cast<std::size_t>(k1)),
        b(static_cast<std::size_t>(nmax_storage), static_cast<std::size_t>(k2)),
        g(static_cast<std::size_t>(nmax_storage), static_cast<std::size_t>(k2)),
        q(xs.size(), static_cast<std::size_t>(k1)) {
    for (int i = 1; i <= m; ++i) {
      x(i) = xs[static_cast<std::size_t>(i - 1)];
      y(i) = ys[static_cast<std::size_t>(i - 1)];
      w(i) = ws[static_cast<std::size_t>(i - 1)];
    }
  }

  void interpolation_knots() {
    const int mk1 = m - k1;
    if (mk1 == 0) return;
    const int k3 = k / 2;
    int i = k2, j = k3 + 2;
    for (int l = 1; l <= mk1; ++l, ++i, ++j) t(i) = (k3 * 2 == k) ? (x(j) + x(j - 1)) * 0.5 : x(j);
  }

  /// sum (w (y - s(x)))^2 with the B-spline values stored in q; the span
  /// bookkeeping follows FITPACK's so that sums are bit-identical.
  double residual_sum(int nk1) {
    double sum = 0.0;
    int l = k2;
    for (int it = 1; it <= m; ++it) {
      if (!(x(it) < t(l) || l > nk1)) ++l;
      int l0 = l - k2;
      double term = 0.0;
      for (int j = 1; j <= k1; ++j) term += c(++l0) * q(it, j);
      sum += (w(it) * (term - y(it))) * (w(it) * (term - y(it)));
    }
    return sum;
  }

  /// One call of FITPACK's fpcurf with iopt 0 or 1. Returns ier.
  int run(int iopt, double s, int nest, double tol, int maxit, int ier) {
    const int nmin = 2 * k1;
    const double acc = tol * s;
    const int nmax = m + k1;
    double fpold = 0.0, fpms = 0.0;
    int nplus = 0;
    bool goto_part2 = false;
    if (s <= 0.0) {
      n = nmax;
      if (nmax > nest) return 1;
      interpolation_knots();
    } else {
      bool restart = true;
      if (iopt != 0 && n != nmin) {
        fp0 = fpint(n);
        fpold = fpint(n - 1);
        nplus = nrdata(n);
        if (fp0 > s) restart = false;
      }
      if (restart) {
        n = nmin;
        fpold = 0.0;
        nplus = 0;
        nrdata(1) = m - 2;
      }
    }
    // Part 1: the number of knots and their positions.
    for (int iter = 1; iter <= m && !goto_part2; ++iter) {
      if (n == nmin) ier = -2;
      int nrint = n - nmin + 1;
      const int nk1 = n - k1;
      for (int j = 1, i = n; j <= k1; ++j, --i) {
        t(j) = x(1);
        t(i) = x(m);
      }
      // Least-squares spline: observation matrix reduced row by row by Givens rotations.
      fp = 0.0;
      for (int i = 1; i <= nk1; ++i) {
        z(i) = 0.0;
        for (int j = 1; j <= k1; ++j) a(i, j) = 0.0;
      }
      int l = k1;
      double h[8];
      for (int it = 1; it <= m; ++it) {
        const double xi = x(it), wi = w(it);
        double yi = y(it) * wi;
        while (!(xi < t(l + 1) || l == nk1)) ++l;
        basis1(t, k, xi, l, h);
        for (int i = 1; i <= k1; ++i) {
          q(it, i) = h[i];
          h[i] *= wi;
        }
        int j = l - k1;
        for (int i = 1; i <= k1; ++i) {
          ++j;
          const double piv = h[i];
          if (piv == 0.0) continue;
          double cs, sn;
          givens(piv, a(j, 1), cs, sn);
          rotate(cs, sn, yi, z(j));
          if (i == k1) break;
          int i2 = 1;
          for (int i1 = i + 1; i1 <= k1; ++i1) {
            ++i2;
            rotate(cs, sn, h[i1], a(j, i2));
          }
        }
        fp += yi * yi;
      }
      if (ier == -2) fp0 = fp;
      fpint(n) = fp0;
      fpint(n - 1) = fpold;
      nrdata(n) = nplus;
      back_substitute(a, z, nk1, k1, c);
      fpms = fp - s;
      if (std::abs(fpms) < acc) return ier;
      if (fpms < 0.0) {
        goto_part2 = true;
        break;
      }
      if (n == nmax) return -1;
      if (n == nest) return 1;
      // How many knots to add now (Dierckx 5.3.2).
      if (ier != 0) {
        nplus = 1;
        ier = 0;
      } else {
        int npl1 = nplus * 2;
        const double rn = nplus;
        if (fpold - fp > acc) npl1 = static_cast<int>(rn * fpms / (fpold - fp));
        nplus = std::min(nplus * 2, std::max({npl1, nplus / 2, 1}));
      }
      fpold = fp;
      // Residual share of each knot interval; a data point on a knot counts half to each side.
      double fpart = 0.0;
      int i = 1;
      l = k2;
      bool is_new = false;
      for (int it = 1; it <= m; ++it) {
        if (!(x(it) < t(l) || l > nk1)) {
          is_new = true;
          ++l;
        }
        int l0 = l - k2;
        double term = 0.0;
        for (int j = 1; j <= k1; ++j) term += c(++l0) * q(it, j);
        term = (w(it) * (term - y(it))) * (w(it) * (term - y(it)));
        fpart += term;
        if (is_new) {
          const double store = term * 0.5;
          fpint(i) = fpart - store;
          ++i;
          fpart = store;
          is_new = false;
        }
      }
      fpint(nrint) = fpart;
      for (int added = 1; added <= nplus; ++added) {
        add_knot(x, t, n, fpint, nrdata, nrint, 1);
        if (n == nmax) {
          interpolation_knots();
          break;
        }
        if (n == nest) break;
      }
    }
    if (!goto_part2) return ier;  // m trials exhausted (cannot happen: n reaches nmax first)
    if (ier == -2) return ier;     // the least-squares polynomial already has fp <= s

    // Part 2: the smoothing spline; find p with f(p) = s.
    derivative_jumps(t, n, k2, b);
    const int nk1 = n - k1;
    double p1 = 0.0, f1 = fp0 - s, p3 = -1.0, f3 = fpms;
    double psum = 0.0;
    for (int i = 1; i <= nk1; ++i) psum += a(i, 1);
    p = nk1 / psum;
    bool ich1 = false, ich3 = false;
    const int n8 = n - nmin;
    constexpr double con1 = 0.1, con9 = 0.9, con4 = 0.04;
    for (int iter = 1; iter <= maxit; ++iter) {
      const double pinv = 1.0 / p;
      for (int i = 1; i <= nk1; ++i) {
        c(i) = z(i);
        g(i, k2) = 0.0;
        for (int j = 1; j <= k1; ++j) g(i, j) = a(i, j);
      }
      double h[8];
      for (int it = 1; it <= n8; ++it) {
        for (int i = 1; i <= k2; ++i) h[i] = b(it, i) * pinv;
        double yi = 0.0;
        for (int j = it; j <= nk1; ++j) {
          const double piv = h[1];
          double cs, sn;
          givens(piv, g(j, 1), cs, sn);
          rotate(cs, sn, yi, c(j));
          if (j == nk1) break;
          const int i2 = j > n8 ? nk1 - j : k1;
          for (int i = 1; i <= i2; ++i) {
            rotate(cs, sn, h[i + 1], g(j, i + 1));
            h[i] = h[i + 1];
          }
          h[i2 + 1] = 0.0;
        }
      }
      back_substitute(g, c, nk1, k2, c);
      fp = residual_sum(nk1);
      fpms = fp - s;
      if (std::abs(fpms) < acc) return ier;
      if (iter == maxit) return 3;
      const double p2 = p, f2 = fpms;
      if (!ich3) {
        if (f2 - f3 <= acc) {  // the initial p was too large
          p3 = p2;
          f3 = f2;
          p *= con4;
          if (p <= p1) p = p1 * con9 + p2 * con1;
          continue;
        }
        if (f2 < 0.0) ich3 = true;
      }
      if (!ich1) {
        if (f1 - f2 <= acc) {  // the initial p was too small
          p1 = p2;
          f1 = f2;
          p /= con4;
          if (p3 < 0.0) continue;
          if (p >= p3) p = p2 * con1 + p3 * con9;
          continue;
        }
        if (f2 > 0.0) ich1 = true;
      }
      if (f2 >= f1 || f2 <= f3) return 2;
      p = rational_root(p1, f1, p2, f2, p3, f3);
    }
    return 3;
  }

  BSpline spline() {
    BSpline s;
    s.degree = k;
    s.knots.assign(t.v.begin() + 1, t.v.begin() + 1 + n);
    s.coefficients.assign(c.v.begin() + 1, c.v.begin() + 1 + (n - k1));
    return s;
  }
};

}  // namespace

bool SmoothingFit::condition_met() const {
  return std::abs(residual - smoothing) < tolerance * smoothing;
}

SmoothingFit univariate_spline(const std::vector<double>& x, const std::vector<double>& y,
                               const std::vector<double>& w, double s, int k, double tol, int maxit) {
  const std::size_t m = x.size();
  if (k < 1 || k > 5) throw std::invalid_argument("smoothing spline: degree must be 1..5");
  if (y.size() != m || w.size() != m) throw std::invalid_argument("smoothing spline: x, y and w differ in length");
  if (m <= static_cast<std::size_t>(k)) throw std::invalid_argument("smoothing spline: needs more data points than the degree");
  if (!(s >= 0.0)) throw std::invalid_argument("smoothing spline: the smoothing factor must be >= 0");
  for (std::size_t i = 0; i < m; ++i) {
    if (!(w[i] > 0.0) || !std::isfinite(y[i]) || !std::isfinite(x[i]))
      throw std::invalid_argument("smoothing spline: weights must be positive and data finite");
    if (i > 0 && !(x[i] > x[i - 1])) throw std::invalid_argument("smoothing spline: x must be strictly increasing");
  }
  Workspace ws(x, y, w, k);
  const int mi = static_cast<int>(m);
  const int full = mi + k + 1;
  // scipy's fpcurf0 starts with nest = max(m/2, 2k+2) when s > 0 ...
  int ier = ws.run(0, s, s > 0.0 ? std::max(mi / 2, 2 * (k + 1)) : full, tol, maxit, 0);
  // ... and on ier = 1 (storage exhausted) UnivariateSpline continues with
  // iopt = 1, nest = m+k+1 and ier = 1 passed back in.
  if (ier == 1 && s > 0.0) ier = ws.run(1, s, full, tol, maxit, 1);
  SmoothingFit fit;
  fit.spline = ws.spline();
  fit.residual = ws.fp;
  fit.smoothing = s;
  fit.tolerance = tol;
  fit.ier = ier;
  fit.p = ws.p;
  fit.polynomial_residual = ws.fp0;
  return fit;
}

double weighted_residual(const BSpline& s, const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& w) {
  double sum = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = w[i] * (y[i] - s(x[i]));
    sum += r * r;
  }
  return sum;
}

const char* describe_ier(int ier) {
  switch (ier) {
    case 0: return "the smoothing condition holds";
    case -1: return "the spline interpolates the data";
    case -2: return "the least-squares cubic already meets the smoothing factor (no interior knots)";
    case 1: return "the knot storage was exhausted (s too small)";
    case 2: return "the iteration for the smoothing parameter behaved abnormally (s too small)";
    case 3: return "the iteration for the smoothing parameter did not converge in maxit steps (s too small)";
    default: return "unknown FITPACK code";
  }
}

}  // namespace stentsim::device_gen::fitpack
