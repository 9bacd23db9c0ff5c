// bvmesh-cad-reader: the child process that parses CAD files and BREP text from outside for the
// core (core/cad/isolated_reader.h), so that OCCT failing on them cannot take the caller down.
//   bvmesh-cad-reader --seconds S --megabytes M -- FILE|-
#include <cstdlib>
#include <iostream>
#include <string>

#include "core/cad/isolated_reader.h"

int main(int argc, char** argv) {
  bvmesh::cad::ReaderLimits limits;
  int a = 1;
  for (; a + 1 < argc && std::string(argv[a]) != "--"; a += 2) {
    const std::string option = argv[a];
    if (option == "--seconds") limits.seconds = std::atof(argv[a + 1]);
    else if (option == "--megabytes") limits.memoryMegabytes = std::atof(argv[a + 1]);
    else break;
  }
  if (a + 1 >= argc || std::string(argv[a]) != "--") {
    std::cerr << "usage: bvmesh-cad-reader --seconds S --megabytes M -- FILE|-\n";
    return 2;
  }
  return bvmesh::cad::runCadReader(argv[a + 1], limits);
}
