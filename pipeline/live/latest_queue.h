// A bounded queue between a live source and a slower consumer (the painter). When it is
// full, a new item pushes out the oldest one (newest wins) and the drop is counted: a live
// source never blocks and memory never grows beyond `capacity` items.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>

namespace fresco {

template <class T>
class LatestQueue {
 public:
  explicit LatestQueue(size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  // Adds `item`; when full, the oldest queued item is dropped first. Never blocks.
  void Push(T item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (items_.size() >= capacity_) {
        items_.pop_front();
        ++dropped_;
      }
      items_.push_back(std::move(item));
      ++pushed_;
      if (items_.size() > high_water_) high_water_ = items_.size();
    }
    ready_.notify_one();
  }

  // No more items will come; Pop returns false once the queue is empty.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  // Waits for the oldest item. False when closed and empty, or after `timeout` with none.
  bool Pop(T* item, std::chrono::milliseconds timeout = std::chrono::hours(24)) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!ready_.wait_for(lock, timeout, [this] { return !items_.empty() || closed_; }))
      return false;
    if (items_.empty()) return false;
    *item = std::move(items_.front());
    items_.pop_front();
    return true;
  }

  size_t capacity() const { return capacity_; }
  long long dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  long long pushed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pushed_;
  }
  // The most items ever held at once (never above capacity).
  size_t high_water() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return high_water_;
  }

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  bool closed_ = false;
  long long dropped_ = 0;
  long long pushed_ = 0;
  size_t high_water_ = 0;
};

}  // namespace fresco
