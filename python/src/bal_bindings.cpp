#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <cmath>

#include "bindings.h"
#include "pnpba/bal/bal_problem.h"
#include "pnpba/bal/bal_solver.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"

namespace pnpba::python {

namespace {

// A writable NumPy view of `values` as rows of `width`, alive as long as `owner` is.
py::array_t<double> rowsView(std::vector<double>& values, py::ssize_t width, py::handle owner) {
  return py::array_t<double>(
      {static_cast<py::ssize_t>(values.size()) / width, width},
      {width * static_cast<py::ssize_t>(sizeof(double)), static_cast<py::ssize_t>(sizeof(double))},
      values.data(), owner);
}

py::object finiteOrNone(double v) { return std::isfinite(v) ? py::cast(v) : py::none(); }

py::dict iterationDict(const BalIteration& it) {
  py::dict d;
  d["iteration"] = it.iteration, d["cost"] = it.cost;
  d["gradient_norm"] = finiteOrNone(it.gradient_norm);
  d["step_norm"] = finiteOrNone(it.step_norm);
  d["lambda"] = finiteOrNone(it.lambda);
  d["time_s"] = it.cum_time_s;
  return d;
}

BalSolveSummary solve(BalProblem& problem, int threads, const std::string& solver,
                      const std::string& linear_solver, bool single_precision,
                      const std::string& robust, int iterations, double function_tolerance,
                      double gradient_tolerance, double parameter_tolerance,
                      const py::object& callback) {
  BalSolveOptions o;
  o.threads = threads, o.solver = solver, o.robust = robust, o.iterations = iterations;
  o.linear_solver = linear_solver;
  o.single_precision = single_precision;
  o.function_tolerance = function_tolerance, o.gradient_tolerance = gradient_tolerance;
  o.parameter_tolerance = parameter_tolerance;
  const std::string problem_text = o.validate();
  if (!problem_text.empty()) throw Error(problem_text);
  // The callback runs with the GIL; an exception it raises stops further calls and is raised
  // again once the solve returns (the solver itself is not interrupted mid-iteration).
  std::function<void(const BalIteration&)> on_iteration;
  std::unique_ptr<py::error_already_set> raised;
  if (!callback.is_none()) {
    on_iteration = [&](const BalIteration& it) {
      if (raised) return;
      py::gil_scoped_acquire acquire;
      try {
        callback(iterationDict(it));
      } catch (py::error_already_set& e) {
        raised = std::make_unique<py::error_already_set>(std::move(e));
      }
    };
  }
  BalSolveSummary summary;
  {
    py::gil_scoped_release release;
    summary = solveBal(problem, o, on_iteration);
  }
  if (raised) throw std::move(*raised);
  return summary;
}

}  // namespace

void bindBal(py::module_& m) {
  py::class_<BalProblem>(m, "BalProblem",
                         "A 'Bundle Adjustment in the Large' problem. cameras and points are "
                         "writable views of the problem's own memory; solve_bal updates them.")
      .def_property_readonly(
          "cameras",
          [](py::object self) { return rowsView(self.cast<BalProblem&>().cameras, 9, self); },
          "N x 9: angle-axis rotation, translation, f, k1, k2")
      .def_property_readonly(
          "points",
          [](py::object self) { return rowsView(self.cast<BalProblem&>().points, 3, self); },
          "M x 3 points")
      .def_property_readonly(
          "observations",
          [](const BalProblem& p) {
            return tableOf<double>(p.observations.size(), 2, [&](size_t i, int k) {
              return k == 0 ? p.observations[i].u : p.observations[i].v;
            });
          },
          "K x 2 observed pixels (u, v), centred as in the BAL files (a copy)")
      .def_property_readonly(
          "camera_index",
          [](const BalProblem& p) {
            return tableOf<int>(p.observations.size(), 0,
                                [&](size_t i, int) { return p.observations[i].camera; });
          },
          "K camera indices of the observations")
      .def_property_readonly(
          "point_index",
          [](const BalProblem& p) {
            return tableOf<int>(p.observations.size(), 0,
                                [&](size_t i, int) { return p.observations[i].point; });
          },
          "K point indices of the observations")
      .def_readonly("num_cameras", &BalProblem::num_cameras)
      .def_readonly("num_points", &BalProblem::num_points)
      .def_property_readonly("num_observations",
                             [](const BalProblem& p) { return p.observations.size(); })
      .def("normalize", &normalizeBal,
           "Ceres bundle_adjuster's normalisation: points centred on their median, scaled to a "
           "median absolute deviation of 100 (projections unchanged)")
      .def(
          "perturb",
          [](BalProblem& p, double rotation_sigma, double translation_sigma, double point_sigma,
             uint64_t seed) {
            perturbBal(p, {rotation_sigma, translation_sigma, point_sigma, seed});
          },
          py::arg("rotation_sigma") = 0.0, py::arg("translation_sigma") = 0.0,
          py::arg("point_sigma") = 0.0, py::arg("seed") = BalPerturbation{}.seed,
          "Adds Gaussian noise (bundle_adjust_bal's --rotation-sigma, ...)")
      .def("cost", &BalProblem::cost, "1/2 sum of squared reprojection errors (Ceres's cost)")
      .def("rms_px", &BalProblem::rmsPixels, "RMS reprojection error per observation, px")
      .def(
          "write",
          [](const BalProblem& p, const std::string& path) {
            writeOutputFile(path, [&p](std::ostream& out) { writeBal(out, p); });
          },
          py::arg("path"), "Writes the problem in BAL format")
      .def(
          "write_ply",
          [](const BalProblem& p, const std::string& path, bool binary) {
            writeOutputFile(path, [&](std::ostream& out) { writeBalPly(out, p, binary); });
          },
          py::arg("path"), py::arg("binary") = true,
          "Camera centres (green) and points (white) as PLY")
      .def("__repr__", [](const BalProblem& p) {
        return "BalProblem(cameras=" + std::to_string(p.num_cameras) +
               ", points=" + std::to_string(p.num_points) +
               ", observations=" + std::to_string(p.observations.size()) + ")";
      });

  py::class_<BalSolveSummary>(m, "BalSummary", "What solve_bal did (costs are 1/2 sum r^2).")
      .def_readonly("ok", &BalSolveSummary::ok)
      .def_readonly("solver", &BalSolveSummary::solver)
      .def_readonly("linear_solver", &BalSolveSummary::linear_solver)
      .def_readonly("single_precision", &BalSolveSummary::single_precision)
      .def_readonly("threads", &BalSolveSummary::threads)
      .def_readonly("peak_memory_mb", &BalSolveSummary::peak_memory_mb)
      .def_readonly("termination", &BalSolveSummary::termination)
      .def_readonly("iterations", &BalSolveSummary::iterations)
      .def_readonly("initial_cost", &BalSolveSummary::initial_cost)
      .def_readonly("final_cost", &BalSolveSummary::final_cost)
      .def_readonly("rms_px_initial", &BalSolveSummary::rms_px_initial)
      .def_readonly("rms_px_final", &BalSolveSummary::rms_px_final)
      .def_readonly("time_s", &BalSolveSummary::time_s)
      .def_property_readonly(
          "table",
          [](const BalSolveSummary& s) {
            py::list rows;
            for (const BalIteration& it : s.table) rows.append(iterationDict(it));
            return rows;
          },
          "per-iteration rows: iteration, cost, gradient_norm, step_norm, lambda, time_s")
      .def("to_json", &balSummaryJson, "the summary bundle_adjust_bal --json writes")
      .def("__repr__", [](const BalSolveSummary& s) {
        return "BalSummary(iterations=" + std::to_string(s.iterations) +
               ", initial_cost=" + std::to_string(s.initial_cost) +
               ", final_cost=" + std::to_string(s.final_cost) + ")";
      });

  m.def("read_bal", &readBal, py::arg("path"),
        "Reads and validates a BAL problem file; raises pnpba.Error naming the file and line.");
  m.def("solve_bal", &solve, py::arg("problem"), py::kw_only(), py::arg("threads") = 1,
        py::arg("solver") = "pnpba", py::arg("linear_solver") = "auto",
        py::arg("single_precision") = false, py::arg("robust") = "none", py::arg("iterations") = 50,
        py::arg("function_tolerance") = 1e-6, py::arg("gradient_tolerance") = 1e-10,
        py::arg("parameter_tolerance") = 1e-8, py::arg("callback") = py::none(),
        R"doc(Bundle-adjusts the problem in place and returns a BalSummary.

solver: 'pnpba' (the dedicated Schur LM), 'ceres-dense_schur', 'ceres-sparse_schur',
'ceres-iterative_schur' (Ceres) or 'native' (the graph engine); linear_solver (pnpba): 'auto',
'dense', 'sparse' or 'cg'; robust:
'none', 'huber' or 'cauchy' (1 px). callback(row) gets each per-iteration row (a dict) as it
happens, row 0 being the initial cost. The GIL is released while solving.)doc");
}

}  // namespace pnpba::python
