# bvmesh_warnings: the warning set every project target builds with.
add_library(bvmesh_warnings INTERFACE)
target_compile_options(bvmesh_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
  -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough
  $<$<BOOL:${BVMESH_WERROR}>:-Werror>)
