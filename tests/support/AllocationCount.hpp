// Counts the allocations this thread makes in a stretch of code: a test binary that links
// AllocationCount.cpp has its operator new count while one of these lives. The real-time
// loop's parts (the streaming runtime, the live front end, the frame events) are held to none.
#pragma once

namespace lipsyncd::test {

class AllocationCount {
  public:
    AllocationCount();
    ~AllocationCount();
    AllocationCount(const AllocationCount&) = delete;
    AllocationCount& operator=(const AllocationCount&) = delete;
    long made() const;  // since this began
};

}  // namespace lipsyncd::test
