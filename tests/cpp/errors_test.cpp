#include "core/common/errors.h"

#include <gtest/gtest.h>

#include <Standard_DomainError.hxx>

#include "core/common/number_text.h"
#include "core/common/occt_errors.h"

namespace bvmesh {
namespace {

TEST(Errors, TopologyErrorIsInvalidInput) {
  EXPECT_THROW(throw TopologyError("edge 3 has three faces"), InvalidInputError);
  EXPECT_THROW(throw InvalidInputError("x"), std::invalid_argument);
  EXPECT_THROW(throw SolverError("x"), std::runtime_error);
}

TEST(Errors, OcctFailureBecomesSolverErrorWithContext) {
  try {
    translateOcctErrors("reading face 4", []() -> int { throw Standard_DomainError("bad knot"); });
    FAIL() << "no exception";
  } catch (const SolverError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("reading face 4"), std::string::npos) << message;
    EXPECT_NE(message.find("Standard_DomainError"), std::string::npos) << message;
    EXPECT_NE(message.find("bad knot"), std::string::npos) << message;
  }
}

TEST(Errors, TranslateOcctErrorsPassesResultsThrough) {
  EXPECT_EQ(translateOcctErrors("adding", [] { return 2 + 3; }), 5);
}

TEST(NumberText, SixSignificantDigitsAtEveryScale) {
  EXPECT_EQ(numberText(1e-9), "1e-09");
  EXPECT_EQ(numberText(0.05), "0.05");
  EXPECT_EQ(numberText(-2.5), "-2.5");
  EXPECT_EQ(numberText(1234567.0), "1.23457e+06");
  EXPECT_EQ(numberText(1e300), "1e+300");
  EXPECT_EQ(coordinatesText(Eigen::Vector3d(1e-7, 0.0, 3.0)), "1e-07, 0, 3");
}

}  // namespace
}  // namespace bvmesh
