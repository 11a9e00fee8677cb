#pragma once
// A loop whose iterations are independent, run on the machine's cores: registration's searches,
// the map's layers and the planner's grid, a stop's work that the robot waits for.

#include <cstddef>
#include <functional>

namespace pitchlab::mapping {

/// Calls `body(begin, end)` over [0, n) in blocks of `block` items, the blocks taken in turn by up
/// to `max_threads` threads (the caller's included; 0: one per core, at most 8). Each item must
/// depend on nothing another item writes, so the result is a plain loop's whatever the threads.
/// With one block, one core, or no thread to be had, the caller runs it all. A body's exception
/// reaches the caller once every thread has stopped.
void ParallelFor(std::size_t n, std::size_t block,
                 const std::function<void(std::size_t begin, std::size_t end)>& body,
                 unsigned max_threads = 0);

/// ParallelFor over the rows [0, rows) of a grid, kGridRowsPerBlock at a time: body(j0, j1) for
/// rows j0 <= j < j1. For a grid pass whose cells depend only on what the pass reads (a map's
/// layers, the planner's grid): the same grid as row after row.
inline constexpr int kGridRowsPerBlock = 16;  // a 641-cell row block: ~0.2-1 ms of work
template <typename RowsBody>
void ParallelRows(int rows, RowsBody&& body) {
  ParallelFor(static_cast<std::size_t>(rows), kGridRowsPerBlock,
              [&](std::size_t j0, std::size_t j1) {
                body(static_cast<int>(j0), static_cast<int>(j1));
              });
}

/// While one lives, the ParallelFor calls its thread makes run on that thread alone: work done
/// beside other work (a registration target prepared while the robot drives) would take the
/// cores that work needs. Made and ended on one thread; they nest.
class SerialLoops {
 public:
  SerialLoops();
  ~SerialLoops();
  SerialLoops(const SerialLoops&) = delete;
  SerialLoops& operator=(const SerialLoops&) = delete;

 private:
  bool was_;
};

}  // namespace pitchlab::mapping
