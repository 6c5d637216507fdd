// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// A task-scheduler runtime for oneTBB's headers that ThreadSanitizer can see, linked only into
// builds configured with -DCMGEOM_SANITIZE=thread (see CMakeLists.txt and doc/Reliability.md).
//
// Why: the system oneTBB library (libtbb.so.12) is not instrumented. Its scheduler hands tasks
// between threads with atomics and futexes that ThreadSanitizer never sees, so every
// tbb::parallel_for reports "data races" between the thread that prepared the data and the worker
// that ran the loop body, and between successive loops (measured: 112 reports for a 14-line
// program that is correct). A suppression broad enough to hide those (any stack through libtbb)
// also hides every real race inside a loop body, which is exactly what the thread build must find.
//
// What: the header-only part of oneTBB (parallel_for, parallel_reduce, parallel_invoke, the
// partitioners, task_arena, global_control) calls a small set of exported entry points
// (tbb::detail::r1::spawn, execute_and_wait, allocate, ...). This file defines them, so the linker
// binds the executable's calls here instead of libtbb.so. Tasks run on real std::threads (the
// caller plus CMGEOM_TSAN_TBB_THREADS - 1 workers, default 1), handed over through a mutex-guarded
// queue, and every wait ends with an acquire of the wait_context counter that finishing tasks
// release. These are the edges TBB documents (a task sees what its spawner did before spawning; the
// waiter sees everything the tasks did), and ThreadSanitizer sees them because they are made of
// instrumented mutexes and atomics. Loop bodies therefore run concurrently with exactly the
// guarantees TBB gives, and a race between two bodies is reported.
//
// Limits (documented in doc/Reliability.md): the shared queue lock orders every hand-over, so two
// tasks that happen not to overlap in time are seen as ordered (a race is reported only when the
// two bodies really overlap); work stealing, affinity and task priorities are not modelled; the
// scheduler itself (libtbb) is not checked. scripts/test.sh verifies that the thread-build binaries
// import no tbb::detail::r1 symbol, i.e. that nothing falls through to the uninstrumented library.
//
// Complexity: O(1) per spawn plus a lock; waiting threads help run queued tasks.
#include <oneapi/tbb/detail/_config.h>
#include <oneapi/tbb/detail/_exception.h>
#include <oneapi/tbb/detail/_small_object_pool.h>
#include <oneapi/tbb/detail/_task.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <mutex>
#include <new>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace tbb {
namespace detail {
namespace r1 {

namespace {

using d1::execution_data;
using d1::slot_id;
using d1::task;
using d1::task_group_context;

// Per task_group_context state, owned by this runtime (the context's my_itt_caller slot, which
// only the library uses, points to it).
struct Context_state {
  std::atomic<bool> cancelled{false};
  std::exception_ptr exception;  // first exception thrown by one of its tasks (under g_mutex)
};

struct Item {
  task* t;
  task_group_context* ctx;
  slot_id origin;
};

std::mutex g_mutex;
std::condition_variable g_cv;
std::deque<Item> g_queue;
std::multiset<std::size_t> g_parallelism_limits;  // active global_control(max_allowed_parallelism)
std::vector<std::thread> g_workers;
bool g_stop = false;

thread_local slot_id t_slot = 0;
thread_local int t_arena_limit = 0;      // max_concurrency of the task_arena being executed (0: none)
thread_local std::vector<Item> t_local;  // tasks spawned while only this thread may run them
thread_local task_group_context* t_context = nullptr;

// The context of the item each thread is running (relaxed atomics: they order nothing). Only a
// waiter whose group was cancelled by an exception reads them, to know when none of its tasks is
// still running (the task that threw never releases its wait_context).
std::vector<std::atomic<task_group_context*>*> g_running;  // under g_mutex
std::atomic<task_group_context*>& running_slot() {
  thread_local std::atomic<task_group_context*>* slot = [] {
    auto* a = new std::atomic<task_group_context*>(nullptr);  // lives as long as the process
    std::lock_guard<std::mutex> lock(g_mutex);
    g_running.push_back(a);
    return a;
  }();
  return *slot;
}

int pool_size() {
  static const int n = [] {
    const char* s = std::getenv("CMGEOM_TSAN_TBB_THREADS");
    const int v = s ? std::atoi(s) : 2;
    return std::clamp(v, 1, 16);
  }();
  return n;
}

int effective_concurrency() {
  int c = pool_size();
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (!g_parallelism_limits.empty()) c = std::min<int>(c, int(*g_parallelism_limits.begin()));
  }
  if (t_arena_limit > 0) c = std::min(c, t_arena_limit);
  return std::max(c, 1);
}

}  // namespace

struct task_group_context_impl {
  static Context_state* state(task_group_context& c) {
    if (c.my_state.load(std::memory_order_relaxed) == task_group_context::state::proxy)
      return state(*c.my_actual_context);
    return static_cast<Context_state*>(c.my_itt_caller);
  }
  // As oneTBB's own initialize(): the constructor leaves the state and the parent uninitialised,
  // and a state that happened to read as `proxy` made state() follow a stray pointer (a rare crash
  // of the thread-sanitizer builds)
  static void create(task_group_context& c) {
    c.my_state.store(task_group_context::state::created, std::memory_order_relaxed);
    c.my_parent = nullptr;
    c.my_itt_caller = new Context_state;
  }
  static void destroy(task_group_context& c) {
    delete static_cast<Context_state*>(c.my_itt_caller);
    c.my_itt_caller = nullptr;
  }
};

struct global_control_impl {
  static std::size_t value(const d1::global_control& g) { return g.my_value; }
  static bool is_parallelism(const d1::global_control& g) {
    return g.my_param == d1::global_control::max_allowed_parallelism;
  }
};

struct task_arena_impl {
  static int max_concurrency(const d1::task_arena_base& a) { return a.my_max_concurrency; }
};

class external_waiter {
public:
  static bool pending(const d1::wait_context& w) { return w.continue_execution(); }
};

namespace {

using Ctx = task_group_context_impl;

// Runs an item and the tasks it bypasses to. Nothing of the item's context is touched once its
// last task has finished: the waiter may return and destroy the context at that moment.
// `outer`: what this thread's running slot held before the item was taken (the slot already
// names the item's context, set where the item left a queue).
void run(Item it, task_group_context* outer) {
  task_group_context* const saved = t_context;
  t_context = it.ctx;
  std::atomic<task_group_context*>& running = running_slot();
  execution_data ed;
  ed.context = it.ctx;
  ed.original_slot = it.origin;
  ed.affinity_slot = d1::no_slot;
  for (task* t = it.t; t;) {
    Context_state* s = Ctx::state(*it.ctx);  // alive: `t` has not finished
    if (s->cancelled.load(std::memory_order_relaxed)) {
      t = t->cancel(ed);
      continue;
    }
    try {
      t = t->execute(ed);
    } catch (...) {
      // As TBB: the first exception cancels the group and is rethrown by its waiter. The task that
      // threw never finalises, so the waiter also stops once nothing of the group is queued or
      // running.
      std::lock_guard<std::mutex> lock(g_mutex);
      if (!s->exception) s->exception = std::current_exception();
      s->cancelled.store(true, std::memory_order_relaxed);
      t = nullptr;
    }
  }
  running.store(outer, std::memory_order_relaxed);
  t_context = saved;
  g_cv.notify_all();
}

bool take(Item& it);

void worker_main(slot_id slot) {
  t_slot = slot;
  for (;;) {
    Item it;
    task_group_context* const outer = running_slot().load(std::memory_order_relaxed);
    {
      std::unique_lock<std::mutex> lock(g_mutex);
      g_cv.wait(lock, [] { return g_stop || !g_queue.empty(); });
      if (g_stop) return;
      it = g_queue.front();
      g_queue.pop_front();
      running_slot().store(it.ctx, std::memory_order_relaxed);  // seen as running from the pop on
    }
    run(it, outer);
    for (Item local; take(local);) run(local, outer);
  }
}

struct Pool {
  Pool() {
    for (int i = 1; i < pool_size(); ++i) g_workers.emplace_back(worker_main, slot_id(i));
  }
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      g_stop = true;
    }
    g_cv.notify_all();
    for (std::thread& t : g_workers) t.join();
  }
};

void ensure_pool() { static Pool pool; }

void push(task& t, task_group_context& ctx) {
  const Item it{&t, &ctx, t_slot};
  if (effective_concurrency() == 1) {
    t_local.push_back(it);
    return;
  }
  ensure_pool();
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_queue.push_back(it);
  }
  g_cv.notify_one();
}

bool take(Item& it) {
  if (!t_local.empty()) {
    it = t_local.back();
    t_local.pop_back();
    running_slot().store(it.ctx, std::memory_order_relaxed);
    return true;
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_queue.empty()) return false;
  it = g_queue.front();
  g_queue.pop_front();
  running_slot().store(it.ctx, std::memory_order_relaxed);
  return true;
}

// After an exception: is any task of `ctx` still queued or running (anywhere but in this waiter)?
bool group_busy(task_group_context* ctx) {
  for (const Item& it : t_local)
    if (it.ctx == ctx) return true;
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const Item& it : g_queue)
    if (it.ctx == ctx) return true;
  for (const auto* r : g_running)
    if (r != &running_slot() && r->load(std::memory_order_relaxed) == ctx) return true;
  return false;
}

void wait_for(d1::wait_context& w, task_group_context& ctx) {
  Context_state* s = Ctx::state(ctx);
  for (;;) {
    if (!external_waiter::pending(w)) break;  // acquire: sees every finished task's writes
    if (s->cancelled.load(std::memory_order_relaxed) && !group_busy(&ctx)) break;
    Item it;
    const auto outer = running_slot().load(std::memory_order_relaxed);
    if (take(it)) {
      run(it, outer);
      continue;
    }
    std::unique_lock<std::mutex> lock(g_mutex);
    g_cv.wait_for(lock, std::chrono::milliseconds(1), [&] { return !g_queue.empty() || !external_waiter::pending(w); });
  }
  std::exception_ptr e;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    std::swap(e, s->exception);
  }
  if (e) std::rethrow_exception(e);
}

}  // namespace

// ------------------------------------------------------------------ exported entry points
void __TBB_EXPORTED_FUNC spawn(d1::task& t, d1::task_group_context& ctx) { push(t, ctx); }
void __TBB_EXPORTED_FUNC spawn(d1::task& t, d1::task_group_context& ctx, d1::slot_id) { push(t, ctx); }

void __TBB_EXPORTED_FUNC execute_and_wait(d1::task& t, d1::task_group_context& t_ctx, d1::wait_context& w,
                                          d1::task_group_context& w_ctx) {
  const auto outer = running_slot().load(std::memory_order_relaxed);
  running_slot().store(&t_ctx, std::memory_order_relaxed);
  run(Item{&t, &t_ctx, t_slot}, outer);
  wait_for(w, w_ctx);
}

void __TBB_EXPORTED_FUNC wait(d1::wait_context& w, d1::task_group_context& ctx) { wait_for(w, ctx); }

d1::slot_id __TBB_EXPORTED_FUNC execution_slot(const d1::execution_data*) { return t_slot; }
d1::task_group_context* __TBB_EXPORTED_FUNC current_context() { return t_context; }
void __TBB_EXPORTED_FUNC notify_waiters(std::uintptr_t) { g_cv.notify_all(); }

void* __TBB_EXPORTED_FUNC allocate(d1::small_object_pool*& pool, std::size_t n, const d1::execution_data&) {
  return allocate(pool, n);
}
void* __TBB_EXPORTED_FUNC allocate(d1::small_object_pool*& pool, std::size_t n) {
  static char dummy;
  pool = reinterpret_cast<d1::small_object_pool*>(&dummy);
  return ::operator new(n, std::align_val_t(d1::task_alignment));
}
void __TBB_EXPORTED_FUNC deallocate(d1::small_object_pool&, void* p, std::size_t, const d1::execution_data&) {
  ::operator delete(p, std::align_val_t(d1::task_alignment));
}
void __TBB_EXPORTED_FUNC deallocate(d1::small_object_pool&, void* p, std::size_t) {
  ::operator delete(p, std::align_val_t(d1::task_alignment));
}
void* __TBB_EXPORTED_FUNC cache_aligned_allocate(std::size_t n) { return ::operator new(n, std::align_val_t(128)); }
void __TBB_EXPORTED_FUNC cache_aligned_deallocate(void* p) { ::operator delete(p, std::align_val_t(128)); }

void __TBB_EXPORTED_FUNC initialize(d1::task_group_context& c) { Ctx::create(c); }
void __TBB_EXPORTED_FUNC destroy(d1::task_group_context& c) { Ctx::destroy(c); }
void __TBB_EXPORTED_FUNC reset(d1::task_group_context& c) {
  Context_state* s = Ctx::state(c);
  s->cancelled.store(false, std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(g_mutex);
  s->exception = nullptr;
}
bool __TBB_EXPORTED_FUNC cancel_group_execution(d1::task_group_context& c) {
  return !Ctx::state(c)->cancelled.exchange(true, std::memory_order_relaxed);
}
bool __TBB_EXPORTED_FUNC is_group_execution_cancelled(d1::task_group_context& c) {
  return Ctx::state(c)->cancelled.load(std::memory_order_relaxed);
}
void __TBB_EXPORTED_FUNC capture_fp_settings(d1::task_group_context&) {}

void __TBB_EXPORTED_FUNC initialize(d1::task_arena_base&) {}
void __TBB_EXPORTED_FUNC terminate(d1::task_arena_base&) {}
bool __TBB_EXPORTED_FUNC attach(d1::task_arena_base&) { return false; }
void __TBB_EXPORTED_FUNC execute(d1::task_arena_base& a, d1::delegate_base& d) {
  const int saved = t_arena_limit;
  t_arena_limit = task_arena_impl::max_concurrency(a);
  try {
    d();
  } catch (...) {
    t_arena_limit = saved;
    throw;
  }
  t_arena_limit = saved;
}
void __TBB_EXPORTED_FUNC wait(d1::task_arena_base&) {}
int __TBB_EXPORTED_FUNC max_concurrency(const d1::task_arena_base* a) {
  const int limit = a ? task_arena_impl::max_concurrency(*a) : 0;
  return limit > 0 ? limit : pool_size();
}
void __TBB_EXPORTED_FUNC isolate_within_arena(d1::delegate_base& d, std::intptr_t) { d(); }
void __TBB_EXPORTED_FUNC enqueue(d1::task& t, d1::task_arena_base*) {
  static d1::task_group_context* ctx = new d1::task_group_context;
  push(t, *ctx);
}
void __TBB_EXPORTED_FUNC enqueue(d1::task& t, d1::task_group_context& ctx, d1::task_arena_base*) { push(t, ctx); }

void __TBB_EXPORTED_FUNC create(d1::global_control& g) {
  if (!global_control_impl::is_parallelism(g)) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_parallelism_limits.insert(global_control_impl::value(g));
}
void __TBB_EXPORTED_FUNC destroy(d1::global_control& g) {
  if (!global_control_impl::is_parallelism(g)) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  const auto it = g_parallelism_limits.find(global_control_impl::value(g));
  if (it != g_parallelism_limits.end()) g_parallelism_limits.erase(it);
}
std::size_t __TBB_EXPORTED_FUNC global_control_active_value(int p) {
  if (p != d1::global_control::max_allowed_parallelism) return 0;
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_parallelism_limits.empty() ? std::size_t(pool_size()) : *g_parallelism_limits.begin();
}

void __TBB_EXPORTED_FUNC throw_exception(d0::exception_id id) {
  switch (id) {
    case d0::exception_id::bad_alloc:
      throw std::bad_alloc();
    case d0::exception_id::nonpositive_step:
      throw std::invalid_argument("Step must be positive");
    case d0::exception_id::out_of_range:
      throw std::out_of_range("Index out of requested size range");
    default:
      throw std::runtime_error("oneTBB exception " + std::to_string(int(id)));
  }
}

void __TBB_EXPORTED_FUNC assertion_failure(const char* location, int line, const char* expression,
                                           const char* comment) {
  std::fprintf(stderr, "oneTBB assertion %s failed at %s:%d: %s\n", expression, location, line, comment ? comment : "");
  std::abort();
}

}  // namespace r1
}  // namespace detail
}  // namespace tbb
