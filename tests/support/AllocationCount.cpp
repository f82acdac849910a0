#include "AllocationCount.hpp"

#include <cstdlib>
#include <new>

// Replacing the global operator new/delete pair with malloc/free is what the standard allows;
// g++ cannot see that the two belong together.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
thread_local int counting = 0;  // AllocationCounts alive on this thread
thread_local long allocations = 0;
}  // namespace

void* operator new(std::size_t n) {
    if (counting > 0) ++allocations;
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}

namespace lipsyncd::test {

AllocationCount::AllocationCount() {
    if (counting++ == 0) allocations = 0;
}
AllocationCount::~AllocationCount() {
    --counting;
}
long AllocationCount::made() const {
    return allocations;
}

}  // namespace lipsyncd::test
