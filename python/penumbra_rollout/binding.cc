// _penumbra_rollout: the pybind11 module of penumbra::BatchStepper (src/penumbra/rollout/).
// arrays cross as NumPy float64, row-major, one row per copy; Step releases the GIL while the
// copies are stepped on the stepper's thread pool. every argument is checked before anything is
// allocated or started (src/penumbra/rollout/rollout_args.h): a bad one raises ValueError naming
// it and its bound (penumbra::ConfigError), a MuJoCo or thread failure RuntimeError; nothing
// exits the process.

#include <mujoco/mujoco.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/rollout/batch_stepper.h"
#include "penumbra/rollout/rollout_args.h"

namespace py = pybind11;
using penumbra::BatchActuation;
using penumbra::BatchStepper;
using penumbra::BatchStepperConfig;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// checks that `a` holds exactly `rows` x `cols` values (a 2-D array of that shape, or a 1-D one
// of that size when rows is 1), else throws ValueError naming the argument.
void CheckShape(const DoubleArray& a, const char* name, py::ssize_t rows, py::ssize_t cols) {
  const bool ok2 = a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == cols;
  const bool ok1 = a.ndim() == 1 && rows == 1 && a.shape(0) == cols;
  if (!ok2 && !ok1) {
    std::string got = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) {
      if (i > 0) got += ", ";
      got += std::to_string(a.shape(i));
    }
    got += a.ndim() == 1 ? ",)" : ")";
    throw py::value_error(std::string(name) + ": got an array of shape " + got + "; expected (" +
                          std::to_string(rows) + ", " + std::to_string(cols) + ")");
  }
}

std::vector<std::string> Names(const mjModel* m, mjtObj type, int count) {
  std::vector<std::string> out;
  for (int i = 0; i < count; ++i) {
    const char* n = mj_id2name(m, type, i);
    out.emplace_back(n ? n : "");
  }
  return out;
}

DoubleArray Rows(int rows, int cols) { return DoubleArray({rows, cols}); }

}  // namespace

PYBIND11_MODULE(_penumbra_rollout, m) {
  m.doc() = "N copies of one MuJoCo model stepped in C++ on a thread pool (penumbra::BatchStepper)";
  // bad arguments are ValueError; other penumbra errors stay RuntimeError (std::runtime_error)
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const penumbra::ConfigError& e) {
      // an argument's error names the argument ("num_threads: got ..."), a file's the file
      const std::string text =
          e.file().empty() ? penumbra::SanitizeForMessage(e.key() + ": " + e.problem(), 2048)
                           : std::string(e.what());
      PyErr_SetString(PyExc_ValueError, text.c_str());
    }
  });
  m.attr("max_threads") = penumbra::MaxRolloutThreads();
  m.attr("max_substeps") = penumbra::kMaxRolloutSubsteps;
  m.attr("max_copies") = penumbra::kMaxRolloutCopies;
  m.attr("max_model_file_bytes") = penumbra::kMaxRolloutModelFileBytes;
  m.def("memory_cap_bytes", &penumbra::RolloutMemoryCap,
        "bytes the copies of one stepper may take together now: the physical memory, or the "
        "room left under the address-space limit (RLIMIT_AS)");
  py::class_<BatchStepper>(m, "BatchStepper")
      .def(py::init([](const std::string& model_path, int64_t num_copies, int64_t num_threads,
                       int64_t substeps, const std::string& actuation, std::vector<double> kp,
                       std::vector<double> kd) {
             // before narrowing to int, opening the file or starting a thread
             penumbra::ValidateRolloutCounts(num_copies, num_threads, substeps);
             BatchStepperConfig c;
             c.num_copies = static_cast<int>(num_copies);
             c.num_threads = static_cast<int>(num_threads);
             c.substeps = static_cast<int>(substeps);
             if (actuation == "direct") {
               c.actuation = BatchActuation::kDirect;
             } else if (actuation == "joint_pd") {
               c.actuation = BatchActuation::kJointPd;
             } else {
               throw py::value_error("actuation: got '" + actuation +
                                     "'; expected 'direct' or 'joint_pd'");
             }
             c.kp = std::move(kp);
             c.kd = std::move(kd);
             return new BatchStepper(model_path, c);
           }),
           py::arg("model_path"), py::arg("num_copies") = 1, py::arg("num_threads") = 0,
           py::arg("substeps") = 1, py::arg("actuation") = "direct",
           py::arg("kp") = std::vector<double>{}, py::arg("kd") = std::vector<double>{},
           "loads the MJCF file (a regular file) and makes num_copies copies of its initial "
           "state. actuation 'direct': step's input is ctrl; 'joint_pd': one joint position "
           "target per actuator, ctrl = kp (target - q) - kd qdot every substep. ValueError "
           "names a bad argument and its bound (num_threads <= max_threads, substeps <= "
           "max_substeps, num_copies <= max_copies and num_copies x copy_bytes <= "
           "memory_cap_bytes())")
      .def(
          "step",
          [](BatchStepper& s, const DoubleArray& input) {
            CheckShape(input, "input", s.num_copies(), s.nu());
            const double* p = input.data();
            py::gil_scoped_release release;
            s.Step(p);
          },
          py::arg("input"),
          "advances every copy by `substeps` physics steps; input (N, nu), finite (else "
          "ValueError naming input[i, j])")
      .def(
          "reset",
          [](BatchStepper& s, int64_t index, const DoubleArray& qpos, const DoubleArray& qvel) {
            if (index < 0 || index >= s.num_copies()) {
              throw py::index_error("index " + std::to_string(index) + " out of range [0, " +
                                    std::to_string(s.num_copies()) + ")");
            }
            CheckShape(qpos, "qpos", 1, s.nq());
            CheckShape(qvel, "qvel", 1, s.nv());
            s.Reset(static_cast<int>(index), qpos.data(), qvel.data());
          },
          py::arg("index"), py::arg("qpos"), py::arg("qvel"),
          "sets copy `index` to (qpos, qvel) at time 0 with ctrl 0, then mj_forward; values "
          "finite (else ValueError naming qpos[i] or qvel[i])")
      .def(
          "read_state",
          [](const BatchStepper& s) {
            auto qpos = Rows(s.num_copies(), s.nq());
            auto qvel = Rows(s.num_copies(), s.nv());
            auto ctrl = Rows(s.num_copies(), s.nu());
            auto sens = Rows(s.num_copies(), s.nsensordata());
            s.ReadState(qpos.mutable_data(), qvel.mutable_data(), ctrl.mutable_data(),
                        sens.mutable_data());
            return py::make_tuple(qpos, qvel, ctrl, sens);
          },
          "(qpos (N, nq), qvel (N, nv), ctrl (N, nu), sensordata (N, nsensordata)) copies")
      .def_property_readonly("num_copies", &BatchStepper::num_copies)
      .def_property_readonly("num_threads", &BatchStepper::num_threads)
      .def_property_readonly("substeps", &BatchStepper::substeps)
      .def_property_readonly("nq", &BatchStepper::nq)
      .def_property_readonly("nv", &BatchStepper::nv)
      .def_property_readonly("nu", &BatchStepper::nu)
      .def_property_readonly("nsensordata", &BatchStepper::nsensordata)
      .def_property_readonly("timestep", &BatchStepper::timestep)
      .def_property_readonly("copy_bytes", &BatchStepper::copy_bytes,
                             "memory one copy takes (bytes), checked against memory_cap_bytes()")
      .def_property_readonly(
          "qpos0",
          [](const BatchStepper& s) {
            const mjModel* m = s.model();
            return std::vector<double>(m->qpos0, m->qpos0 + m->nq);
          },
          "the model's initial qpos (nq)")
      .def_property_readonly(
          "actuator_names",
          [](const BatchStepper& s) { return Names(s.model(), mjOBJ_ACTUATOR, s.model()->nu); })
      .def_property_readonly(
          "actuator_joints",
          [](const BatchStepper& s) {
            const mjModel* m = s.model();
            std::vector<std::string> out;
            for (int a = 0; a < m->nu; ++a) {
              const int j = m->actuator_trntype[a] == mjTRN_JOINT ? m->actuator_trnid[2 * a] : -1;
              const char* n = j >= 0 ? mj_id2name(m, mjOBJ_JOINT, j) : nullptr;
              out.emplace_back(n ? n : "");
            }
            return out;
          },
          "name of the joint each actuator drives ('' if not a joint)")
      .def_property_readonly(
          "joint_names",
          [](const BatchStepper& s) { return Names(s.model(), mjOBJ_JOINT, s.model()->njnt); })
      .def_property_readonly("joint_qpos_adr",
                             [](const BatchStepper& s) {
                               const mjModel* m = s.model();
                               return std::vector<int>(m->jnt_qposadr, m->jnt_qposadr + m->njnt);
                             })
      .def_property_readonly("joint_dof_adr",
                             [](const BatchStepper& s) {
                               const mjModel* m = s.model();
                               return std::vector<int>(m->jnt_dofadr, m->jnt_dofadr + m->njnt);
                             })
      .def_property_readonly("joint_range",
                             [](const BatchStepper& s) {
                               const mjModel* m = s.model();
                               std::vector<std::vector<double>> out;
                               for (int j = 0; j < m->njnt; ++j)
                                 out.push_back({m->jnt_range[2 * j], m->jnt_range[2 * j + 1]});
                               return out;
                             })
      .def_property_readonly(
          "actuator_ctrlrange",
          [](const BatchStepper& s) {
            const mjModel* m = s.model();
            std::vector<std::vector<double>> out;
            for (int a = 0; a < m->nu; ++a)
              out.push_back({m->actuator_ctrlrange[2 * a], m->actuator_ctrlrange[2 * a + 1]});
            return out;
          })
      .def_property_readonly(
          "sensor_names",
          [](const BatchStepper& s) { return Names(s.model(), mjOBJ_SENSOR, s.model()->nsensor); })
      .def_property_readonly("sensor_adr",
                             [](const BatchStepper& s) {
                               const mjModel* m = s.model();
                               return std::vector<int>(m->sensor_adr, m->sensor_adr + m->nsensor);
                             })
      .def_property_readonly("sensor_dim", [](const BatchStepper& s) {
        const mjModel* m = s.model();
        return std::vector<int>(m->sensor_dim, m->sensor_dim + m->nsensor);
      });
}
