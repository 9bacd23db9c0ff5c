#include "core/common/errors.h"

#include <gtest/gtest.h>

#include <Standard_DomainError.hxx>

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

}  // namespace
}  // namespace bvmesh
