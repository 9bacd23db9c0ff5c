// numpy <-> Eigen conversions shared by the bindings: every array argument is checked here and a
// wrong shape or type raises ValueError naming the argument and the shape it got.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include <cmath>
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

// A point or direction: any sequence or array of three numbers; another length or a non-number
// is an error naming the argument (numpy's own reshape message names nothing).
inline Eigen::Vector3d vector3Of(const pybind11::object& object, const char* name) {
  const DoubleArray array = DoubleArray::ensure(object);
  if (!array || array.size() != 3) {
    throw pybind11::value_error(std::string(name) + " must be 3 numbers (x, y, z), got " +
                                (array ? "shape " + shapeText(array) : std::string(pybind11::repr(object))));
  }
  return Eigen::Vector3d(array.data()[0], array.data()[1], array.data()[2]);
}

// A 1-D sequence of integer ids, copied. Only integer data is taken (Python ints, numpy integer
// arrays and scalars); floats, strings and bools are refused rather than truncated or parsed, and
// values outside the core's 32-bit ids are an error naming the argument, never wrapped.
inline std::vector<int> intsOf(const pybind11::object& object, const char* name) {
  const pybind11::array array = pybind11::array::ensure(object);
  if (!array || array.ndim() != 1) throw pybind11::value_error(std::string(name) + " must be a 1-D sequence of integers");
  if (array.size() == 0) return {};
  const char kind = array.dtype().kind();
  if (kind != 'i' && kind != 'u') {
    throw pybind11::value_error(std::string(name) + " must be integers, got values of numpy type " +
                                std::string(pybind11::str(array.dtype())));
  }
  std::vector<int> result(static_cast<size_t>(array.size()));
  auto take = [&](const auto& values) {
    for (pybind11::ssize_t k = 0; k < array.size(); ++k) {
      const auto value = values.data()[k];
      if (value > 0x7fffffff || (value < 0 && static_cast<long long>(value) < -0x7fffffffLL - 1)) {
        throw pybind11::value_error(std::string(name) + "[" + std::to_string(k) + "] = " + std::to_string(value) +
                                    " does not fit the core's 32-bit ids");
      }
      result[static_cast<size_t>(k)] = static_cast<int>(value);
    }
  };
  if (kind == 'u' && array.itemsize() == 8) {
    take(pybind11::array_t<unsigned long long, pybind11::array::c_style | pybind11::array::forcecast>::ensure(array));
  } else {
    take(pybind11::array_t<long long, pybind11::array::c_style | pybind11::array::forcecast>::ensure(array));
  }
  return result;
}

inline bool isNumpyScalar(const pybind11::handle& value, const char* type) {
  return pybind11::isinstance(value, pybind11::module_::import("numpy").attr(type));
}

// An option that is a real number (Python int / float, numpy number), finite; bools and strings
// are refused with the option's name.
inline double realOption(const pybind11::handle& value, const char* name) {
  const bool number = !pybind11::isinstance<pybind11::bool_>(value) && !isNumpyScalar(value, "bool_") &&
                      (pybind11::isinstance<pybind11::float_>(value) || pybind11::isinstance<pybind11::int_>(value) ||
                       isNumpyScalar(value, "number"));
  if (!number) {
    throw pybind11::value_error(std::string(name) + " must be a number, got " + std::string(pybind11::repr(value)));
  }
  const double result = value.cast<double>();
  if (!std::isfinite(result)) throw pybind11::value_error(std::string(name) + " must be finite, got " + std::to_string(result));
  return result;
}

// An option that is an integer (Python int, numpy integer) in the 32-bit range; 2.5, '3' and True
// are refused with the option's name.
inline int integerOption(const pybind11::handle& value, const char* name) {
  const bool integer = !pybind11::isinstance<pybind11::bool_>(value) &&
                       (pybind11::isinstance<pybind11::int_>(value) || isNumpyScalar(value, "integer"));
  if (!integer) {
    throw pybind11::value_error(std::string(name) + " must be an integer, got " + std::string(pybind11::repr(value)));
  }
  const long long result = pybind11::int_(pybind11::reinterpret_borrow<pybind11::object>(value)).cast<long long>();
  if (result < -0x7fffffffLL - 1 || result > 0x7fffffffLL) {
    throw pybind11::value_error(std::string(name) + " = " + std::to_string(result) + " is out of range");
  }
  return static_cast<int>(result);
}

// An option that is True or False (a Python or numpy bool).
inline bool flagOption(const pybind11::handle& value, const char* name) {
  if (!pybind11::isinstance<pybind11::bool_>(value) && !isNumpyScalar(value, "bool_")) {
    throw pybind11::value_error(std::string(name) + " must be True or False, got " + std::string(pybind11::repr(value)));
  }
  return value.cast<bool>();
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
