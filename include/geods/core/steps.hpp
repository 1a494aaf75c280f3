#pragma once
// A computation that runs in steps: a C++20 coroutine that suspends at each
// `co_yield Steps::pause`. It lets a build be written top to bottom like a
// plain loop and still be spread over many calls (the worst-case dynamization
// builds its next structure a little at every insert).
#include <coroutine>
#include <exception>
#include <utility>

namespace geods {

class Steps {
 public:
  struct Pause {};
  static constexpr Pause pause{};

  struct promise_type {
    std::exception_ptr error;
    Steps get_return_object() { return Steps(std::coroutine_handle<promise_type>::from_promise(*this)); }
    std::suspend_always initial_suspend() noexcept { return {}; }
    std::suspend_always final_suspend() noexcept { return {}; }
    std::suspend_always yield_value(Pause) noexcept { return {}; }
    void return_void() {}
    void unhandled_exception() { error = std::current_exception(); }
  };

  Steps() = default;
  Steps(Steps&& other) noexcept : handle_(std::exchange(other.handle_, {})) {}
  Steps& operator=(Steps&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, {});
    }
    return *this;
  }
  Steps(const Steps&) = delete;
  Steps& operator=(const Steps&) = delete;
  ~Steps() { reset(); }

  bool done() const { return !handle_ || handle_.done(); }

  /// Runs until the next pause or the end; returns done(). Rethrows what the computation threw.
  bool resume() {
    if (done()) return true;
    handle_.resume();
    if (handle_.promise().error) std::rethrow_exception(std::exchange(handle_.promise().error, {}));
    return handle_.done();
  }

 private:
  explicit Steps(std::coroutine_handle<promise_type> handle) : handle_(handle) {}
  void reset() {
    if (handle_) handle_.destroy();
    handle_ = {};
  }

  std::coroutine_handle<promise_type> handle_;
};

}  // namespace geods
