// Work spread over the hardware threads in chunks of consecutive indices. The first exception a
// chunk throws stops the others and is rethrown to the caller; a thread that cannot be created
// (resource limits) leaves its share to the threads that could.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace bvmesh {

// Calls work(begin, end) for consecutive ranges covering [0, count), at most `chunk` long, on up
// to `threads` threads (0: the hardware's; never more than 4 per hardware thread).
template <class Work>
void parallelChunks(std::int64_t count, std::int64_t chunk, Work&& work, unsigned threads = 0) {
  if (count <= 0) return;
  chunk = std::max<std::int64_t>(1, chunk);
  const std::int64_t chunks = (count + chunk - 1) / chunk;
  // More threads than a few per core only cost memory (each has a stack): at most 4 per core.
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const auto wanted = static_cast<std::int64_t>(threads > 0 ? std::min(threads, 4 * hardware) : hardware);
  const std::int64_t threadCount = std::max<std::int64_t>(1, std::min(wanted, chunks));
  std::atomic<std::int64_t> next{0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  auto worker = [&] {
    try {
      for (std::int64_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
        work(c * chunk, std::min(count, (c + 1) * chunk));
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failureMutex);
      if (!failure) failure = std::current_exception();
      next = chunks;
    }
  };
  std::vector<std::thread> pool;
  for (std::int64_t t = 1; t < threadCount; ++t) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the running ones take the rest
    }
  }
  worker();
  for (std::thread& thread : pool) thread.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace bvmesh
