// bvmesh-cad-reader: the child process that parses CAD files and BREP text from outside for the
// core (core/cad/isolated_reader.h), so that OCCT failing on them cannot take the caller down.
//   bvmesh-cad-reader --seconds S --megabytes M [--sew TOLERANCE|off] -- FILE|-
// (--sew 0: automatic tolerance, the default)
#include <cstdlib>
#include <iostream>
#include <string>

#include "core/cad/isolated_reader.h"

int main(int argc, char** argv) {
  bvmesh::cad::ReaderLimits limits;
  bvmesh::cad::RepairOptions repair;
  int a = 1;
  for (; a + 1 < argc && std::string(argv[a]) != "--"; a += 2) {
    const std::string option = argv[a];
    if (option == "--seconds") limits.seconds = std::atof(argv[a + 1]);
    else if (option == "--megabytes") limits.memoryMegabytes = std::atof(argv[a + 1]);
    else if (option == "--sew") {
      repair.sew = std::string(argv[a + 1]) != "off";
      repair.tolerance = repair.sew ? std::atof(argv[a + 1]) : 0.0;
    }
    else break;
  }
  if (a + 1 >= argc || std::string(argv[a]) != "--") {
    std::cerr << "usage: bvmesh-cad-reader --seconds S --megabytes M [--sew TOLERANCE|off] -- FILE|-\n";
    return 2;
  }
  return bvmesh::cad::runCadReader(argv[a + 1], limits, repair);
}
