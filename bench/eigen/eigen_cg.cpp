// Eigen's ConjugateGradient (diagonal preconditioner, GranOO's solver) on a CSR system written
// by bench/bench_scale.py: <prefix>.bin = int64 n, int64 nnz, double rtol, int64 repeat,
// then indptr (n+1 int64), indices (nnz int64), data (nnz double), b (n double).
// Prints one JSON line: best solve time of `repeat` (compute() + solve(), from zero), the
// iterations, Eigen's error estimate and the true relative residual.
#include <Eigen/Sparse>
#include <Eigen/IterativeLinearSolvers>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) { std::fprintf(stderr, "usage: eigen_cg system.bin\n"); return 2; }
  std::FILE* f = std::fopen(argv[1], "rb");
  if (!f) { std::fprintf(stderr, "cannot open %s\n", argv[1]); return 2; }
  int64_t n, nnz, repeat; double rtol;
  if (std::fread(&n, 8, 1, f) != 1 || std::fread(&nnz, 8, 1, f) != 1 || std::fread(&rtol, 8, 1, f) != 1 ||
      std::fread(&repeat, 8, 1, f) != 1) { std::fprintf(stderr, "bad header\n"); return 2; }
  std::vector<int64_t> ip(n + 1), ix(nnz); std::vector<double> v(nnz), bv(n);
  if (std::fread(ip.data(), 8, n + 1, f) != (size_t)(n + 1) || std::fread(ix.data(), 8, nnz, f) != (size_t)nnz ||
      std::fread(v.data(), 8, nnz, f) != (size_t)nnz || std::fread(bv.data(), 8, n, f) != (size_t)n) {
    std::fprintf(stderr, "short file\n"); return 2;
  }
  std::fclose(f);
  std::vector<Eigen::Triplet<double>> t; t.reserve(nnz);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t k = ip[i]; k < ip[i + 1]; ++k) t.emplace_back((int)i, (int)ix[k], v[k]);
  Eigen::SparseMatrix<double, Eigen::RowMajor> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::Map<Eigen::VectorXd> b(bv.data(), n);
  Eigen::VectorXd x;
  double best = 1e300; long iters = 0; double err = 0;
  for (int64_t r = 0; r < repeat; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double, Eigen::RowMajor>, Eigen::Lower | Eigen::Upper,
                             Eigen::DiagonalPreconditioner<double>> cg;
    cg.setTolerance(rtol);
    cg.setMaxIterations(10 * n + 10);
    cg.compute(A);
    x = cg.solve(b);
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (ms < best) best = ms;
    iters = cg.iterations(); err = cg.error();
  }
  double res = (A * x - b).norm() / b.norm();
  std::printf("{\"eigen_ms\": %.6f, \"eigen_iterations\": %ld, \"eigen_error\": %.3e, \"eigen_residual\": %.3e, "
              "\"eigen_threads\": %d}\n", best, iters, err, res, Eigen::nbThreads());
  return 0;
}
