// numpy <-> Eigen conversions shared by the bindings: every array argument is checked here and a
// wrong shape or type raises ValueError naming the argument and the shape it got.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace bvmesh::python {

using DoubleArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;
using IntArray = pybind11::array_t<int, pybind11::array::c_style | pybind11::array::forcecast>;
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// "(3, 4)" or "(5,)".
inline std::string shapeText(const pybind11::array& array) {
  std::string text = "(";
  for (pybind11::ssize_t k = 0; k < array.ndim(); ++k) text += (k > 0 ? ", " : "") + std::to_string(array.shape(k));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

// An (n, columns) array of numbers, copied. An empty sequence ([], numpy shape (0,)) is n = 0.
inline RowMatrixXd rowsOf(const pybind11::object& object, const char* name, pybind11::ssize_t columns) {
  const DoubleArray array = DoubleArray::ensure(object);
  const std::string expected = "(n, " + std::to_string(columns) + ")";
  if (!array) throw pybind11::value_error(std::string(name) + " must be a numeric array of shape " + expected);
  if (array.ndim() == 1 && array.shape(0) == 0) return RowMatrixXd(0, columns);
  if (array.ndim() != 2 || array.shape(1) != columns) {
    throw pybind11::value_error(std::string(name) + " must have shape " + expected + ", got " + shapeText(array));
  }
  return Eigen::Map<const RowMatrixXd>(array.data(), array.shape(0), columns);
}

// A 1-D sequence of integers, copied.
inline std::vector<int> intsOf(const pybind11::object& object, const char* name) {
  const IntArray array = IntArray::ensure(object);
  if (!array || array.ndim() != 1) throw pybind11::value_error(std::string(name) + " must be a 1-D sequence of integers");
  return std::vector<int>(array.data(), array.data() + array.size());
}

// (n, 3) rows as a new numpy array.
template <class Rows>
pybind11::array_t<double> rowsArray(const Rows& rows) {
  pybind11::array_t<double> array({static_cast<pybind11::ssize_t>(rows.rows()), pybind11::ssize_t{3}});
  for (Eigen::Index r = 0; r < rows.rows(); ++r) {
    for (Eigen::Index x = 0; x < 3; ++x) array.mutable_at(r, x) = rows(r, x);
  }
  return array;
}

// (ni, nj, nk, 3) from rows of a structured block with i fastest (row i + ni (j + nj k)).
template <class Rows>
pybind11::array_t<double> gridArray(const Rows& rows, pybind11::ssize_t ni, pybind11::ssize_t nj, pybind11::ssize_t nk) {
  pybind11::array_t<double> array({ni, nj, nk, pybind11::ssize_t{3}});
  auto out = array.template mutable_unchecked<4>();
  for (pybind11::ssize_t k = 0; k < nk; ++k) {
    for (pybind11::ssize_t j = 0; j < nj; ++j) {
      for (pybind11::ssize_t i = 0; i < ni; ++i) {
        for (pybind11::ssize_t x = 0; x < 3; ++x) out(i, j, k, x) = rows(i + ni * (j + nj * k), x);
      }
    }
  }
  return array;
}

}  // namespace bvmesh::python
