"""Many recordings at once on Dask distributed: one task per recording.

    from evlife import batch

    if __name__ == "__main__":   # a script must guard what starts a LocalCluster
        table = batch.process_files(paths, "out/", window_size=7)   # LocalCluster here
        table = batch.process_files(paths, "out/", scheduler="tcp://host:8786")
        print(table)

Without the guard a script would hang: Dask starts the LocalCluster's workers
as new Python processes that import the script again (multiprocessing's
spawn), so each worker would start a cluster of its own and die, and Dask
would restart them for ever. So a LocalCluster started from a script's top
level outside the guard is refused with a RuntimeError naming the line.
Interactive sessions and notebooks need no guard.

One long recording can also be cut into time slices processed in parallel,
each estimator starting a warm-up before its slice (process_slices); the result
then differs slightly from one pass (see the README for the measured share).

Each task of process_files runs `evlife process PATH -o OUT_DIR/NAME.bin` in the worker
(evlife.process_file: the same bytes as the command line, constant memory, the
GIL released), so the workers need evlife importable (PYTHONPATH or an
installed package) and the paths readable where they run.
"""
import contextlib
import functools
import inspect
import math
import operator
import os
import shutil
import signal
import sys
import threading
import time
import uuid
import warnings
import zlib
from collections import Counter, namedtuple

from . import _evlife
from . import _streams
from ._arguments import checking

__all__ = ["FileResult", "BatchResult", "local_cluster", "process_files", "process_slices"]

FileResult = namedtuple("FileResult", "path events lifetime_share seconds output error")
FileResult.__doc__ = """One recording's row: path, events, lifetime_share (share of events
with a lifetime, 0..1), seconds (in the worker; NaN where not known: its worker
died, or the task was interrupted before it finished), output (the written file),
error (None, or the message of the failure; the events before an input
fault are still written, as the command line does: events counts them, 0
where the fault came before the output was opened, and output is then None;
events is None for other failures and for a recording interrupted before it
finished)."""


class BatchResult(list):
    """The rows of process_files, in the order of the paths (a list of FileResult)."""

    @property
    def failed(self):
        """The rows whose recording failed."""
        return [r for r in self if r.error is not None]

    def to_pandas(self):
        """The table as a pandas DataFrame (needs pandas)."""
        import pandas
        return pandas.DataFrame(list(self), columns=FileResult._fields)

    def __str__(self):
        lines = ["%-40s %12s %9s %9s  %s" % ("path", "events", "lifetime", "seconds", "status")]
        for r in self:
            share = "" if r.lifetime_share is None else "%.1f %%" % (100.0 * r.lifetime_share)
            seconds = "" if math.isnan(r.seconds) else "%.2f" % r.seconds  # not known: blank, as events
            lines.append("%-40s %12s %9s %9s  %s" % (
                _short(r.path, 40), "" if r.events is None else r.events, share, seconds,
                "ok" if r.error is None else "FAILED: " + _first_line(r.error)))
        return "\n".join(lines)


def _short(text, width):
    return text if len(text) <= width else "..." + text[-(width - 3):]


def _output_names(paths, extension, out_dir=None):
    """OUT names from the recordings' names, made unique (a.bin, a-2.bin): checked
    against every name given out so far, without regard to case (a recording
    named a-2 must not take a-2.bin from the second a, nor A.bin a.bin's place
    on a case-insensitive file system), and against the recordings themselves
    when they lie in out_dir (x.mat's x.csv must not overwrite the input x.csv)."""
    names, taken = [], set()
    if out_dir is not None:
        here = os.path.realpath(out_dir)
        # The file's own name (a link elsewhere to out_dir/a.h5 reserves a.h5:
        # another recording's a.h5 overwrote it), and the name of a link or
        # hard link in out_dir (out_dir/link.h5 was given out as its output).
        for p in map(os.fspath, paths):
            for name_path in (os.path.realpath(p), os.path.join(os.path.realpath(os.path.dirname(p) or "."),
                                                                 os.path.basename(p))):
                if os.path.dirname(name_path) == here:
                    taken.add(os.path.basename(name_path).lower())
    next_number = {}  # per stem: where its search for a free a-N resumes (from 2 each time: quadratic)
    for p in paths:
        # A folder given with its slash (a rosbag2 bag, as the shell completes it) is named by the folder.
        stem = os.path.splitext(os.path.basename(os.path.normpath(p)))[0] or "recording"
        name, n = stem + extension, next_number.get(stem.lower(), 1)
        while name.lower() in taken:
            n += 1
            name = "%s-%d%s" % (stem, n, extension)
        next_number[stem.lower()] = n
        taken.add(name.lower())
        names.append(name)
    return names


# The output formats of evlife.process_file, by extension (its writers).
OUTPUT_EXTENSIONS = (".bin", ".csv", ".h5", ".hdf5")


def _first_line(error):
    return error.splitlines()[0] if error else error


def _size_or_zero(path):
    """Bytes of a recording (a folder, e.g. a rosbag2 bag, or a missing file: 0)."""
    try:
        return os.path.getsize(path) if os.path.isfile(path) else 0
    except OSError:
        return 0


def _partial_name(output, run):
    """Where the task of call `run` writes its output until it ends, then
    renames it (the extension kept: it names the format). The call's random
    id in the name: no recording, earlier output or other task's file has it.
    A worker stopped mid-write leaves no file under the output's name that
    reads as a shorter recording, and no earlier file of that name replaced."""
    folder, name = os.path.split(output)
    partial = ".evlife-partial-%s.%s" % (run, name)
    try:
        name_max = os.pathconf(folder or ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        name_max = 255
    over = len(os.fsencode(partial)) - name_max
    if over <= 0:
        return os.path.join(folder, partial)
    # A name the output has room for but its partial has not (the prefix's 25
    # bytes): the stem cut, the extension kept (it names the format), and a
    # hash of the whole name that keeps two such outputs apart.
    stem, ext = os.path.splitext(name)
    tag = "%08x" % (zlib.crc32(os.fsencode(name)) & 0xFFFFFFFF)
    room = max(0, len(os.fsencode(stem)) - over - len(tag) - 1)
    return os.path.join(folder, ".evlife-partial-%s.%s.%s%s" % (run, tag, os.fsdecode(os.fsencode(stem)[:room]), ext))


# progress=True: a line on stderr whenever no task has finished for this long, so a
# recording that takes an hour does not leave its batch silent for an hour.
STILL_RUNNING_EVERY_S = 30.0


def _duration_text(seconds):
    seconds = int(seconds)
    return "%d s" % seconds if seconds < 120 else "%d min %02d s" % divmod(seconds, 60)


class _StillRunning:
    """While its `with` lasts, a thread that prints, whenever no task has
    finished for STILL_RUNNING_EVERY_S, how long that has been and the files
    being written: files(), called then, gives (name, path) pairs, and those
    that exist are shown with their size (a cluster whose workers write where
    this process cannot see shows none). finished(line) prints a task's line
    (under the same lock: two threads, whole lines) and restarts the clock."""

    def __init__(self, enabled, what, files):
        self._enabled, self._what, self._files = enabled, what, files
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._last = time.monotonic()
        self._thread = threading.Thread(target=self._watch, name="evlife.batch progress", daemon=True)

    def __enter__(self):
        if self._enabled:
            self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()

    def finished(self, line):
        with self._lock:
            self._last = time.monotonic()
            if self._enabled:
                print(line, file=sys.stderr, flush=True)

    def _watch(self):
        while True:
            with self._lock:
                due = self._last + STILL_RUNNING_EVERY_S - time.monotonic()
            if self._stop.wait(max(due, 0.0)):
                return
            with self._lock:
                quiet_s = time.monotonic() - self._last
                if quiet_s < STILL_RUNNING_EVERY_S:
                    continue  # a task finished meanwhile
                written = []
                for name, path in self._files():
                    with contextlib.suppress(OSError):
                        written.append("%s (%.1f MB)" % (name, os.path.getsize(path) / 1e6))
                print("evlife.batch: %s; none finished for %s%s" % (
                    self._what(), _duration_text(quiet_s),
                    "; writing: " + ", ".join(written) if written else ""), file=sys.stderr, flush=True)
                self._last = time.monotonic()  # the next line after as long again


def _stopped(stop, client=None):
    """Whether the call that submitted this task has given up on it (its Dask
    Event `stop` set: _give_up); `client`: this worker's _reaching_client(),
    looked up when not given. A scheduler out of reach counts as stopped:
    Ctrl-C in a terminal reaches the workers of a LocalCluster started by the
    same script too, and ends their connection while the task's thread runs
    on (the task then renamed its output after the call had raised); a
    worker that lost its scheduler cannot deliver the task's result anyway
    (Dask runs the task again elsewhere, or reports it lost)."""
    from distributed import Event
    client = client or _reaching_client()
    try:
        return client is None or Event(stop, client=client).is_set()
    except Exception:  # whatever the connection raises (its rpc gone: AttributeError)
        return True


def _reaching_client():
    """This worker's Dask client while it is connected to the scheduler,
    else None (a client reconnecting would hold a Lock's acquire for its
    whole timeout)."""
    from distributed import get_client
    try:
        client = get_client()
    except Exception:  # no client to be had: no scheduler
        return None
    return client if client.status == "running" else None


def _give_up(client, stop, futures):
    """The call gives up on its tasks (Ctrl-C; for slices also a failed one):
    none may write after it. Dask cannot stop a running task, and a queued
    one can start before the cancel reaches its worker. So the Event `stop`
    is set first, and each task checks it when it starts and again once its
    file is whole: either the task sees it and removes its file, or its file
    was in place before the Event was set and the call, which looks after
    setting it, finds it. A slice's part is in place as soon as it is whole;
    a recording's output is renamed into place after the check, so the check
    and the rename hold the Lock `stop` (_replace_unless_stopped), as the
    setting does. The Event stays set on the scheduler (a few bytes per
    interrupted call)."""
    from distributed import Event, Lock
    with contextlib.suppress(Exception):  # a scheduler gone: nothing runs
        if client.status != "running":  # its scheduler lost: nothing to set nor cancel (an acquire would wait 10 s)
            return
        lock = Lock(stop, client=client)
        held = lock.acquire(timeout=10)  # a task holds it for one rename; a worker that died holding it: 10 s
        try:
            Event(stop, client=client).set()
        finally:
            if held:
                lock.release()
    client.cancel([f for f in futures if not f.done()])


def _replace_unless_stopped(partial, output, stop):
    """os.replace(partial, output), unless the call has given up on this task
    (_give_up): then `partial` is removed and False returned. Holding the
    call's Lock, which it holds to set its Event: the rename comes before the
    setting (the call then finds the output) or the task sees the Event."""
    from distributed import Lock
    lock, held, client = None, False, _reaching_client()
    with contextlib.suppress(Exception):  # a scheduler out of reach: _stopped() says stopped
        if client is not None:
            lock = Lock(stop, client=client)
            held = lock.acquire(timeout=60)  # the call holds it for one message
    try:
        if _stopped(stop, client):
            _streams._remove(partial)
            return False
        os.replace(partial, output)
        return True
    finally:
        if held:
            with contextlib.suppress(Exception):
                lock.release()


_NOTHING_WRITTEN = "interrupted before it finished; nothing written"


def _process_one(path, output, run, sensor, config, one_thread, crop, options, stop):
    """The task: runs in a worker (the output renamed there: the client may
    not see the worker's files); never raises (a failure is the row's error).
    Returns (row, its warnings as (text, category)) for the caller to warn of.
    stop: the call's Event (_give_up): then nothing is written."""
    start = time.perf_counter()
    if _stopped(stop):
        return FileResult(path, None, None, math.nan, None, _NOTHING_WRITTEN), []
    partial = _partial_name(output, run)
    try:
        _streams._remove(partial)  # a retry's (a worker died): not this attempt's
        from evlife import _evlife as core
        # Kept for the caller (process_files warns at its line): the worker printed
        # them on its stderr at Dask's line (distributed/worker.py), never caught.
        # Per thread: a worker of several threads, or the caller's own process
        # (LocalCluster(processes=False)), runs several tasks at once.
        with _warnings_of_this_thread() as warned:
            r = core.process_file(path, partial, sensor, config=config, one_thread=one_thread, **crop, **options)
        events, share, error = r["events"], (r["with_lifetime"] / r["events"] if r["events"] else 0.0), None
        # What the row has no field for, as evlife.process warns of it: rejected events, skipped records.
        warned = [(str(w.message), w.category) for w in warned] + [
            (text, RuntimeWarning) for text in core._dropped_warnings("evlife.batch.process_files", path, r)]
    except Exception as e:  # reported by name in the table, the other files go on
        warned = []
        # An input fault leaves the events before it written: the row counts
        # them (0 where it came before the output was opened: no output, and a
        # file of the output's name left as it was, as the command line does).
        events, share, error = getattr(e, "events_written", None), None, "%s: %s" % (type(e).__name__, e)
    if not os.path.exists(partial):
        output = None
    else:
        try:
            if not _replace_unless_stopped(partial, output, stop):  # the call gave up on it: nothing written
                return FileResult(path, None, None, math.nan, None, _NOTHING_WRITTEN), []
        except OSError as e:  # e.g. a folder of the output's name
            _streams._remove(partial)
            error = error or "cannot write %s: %s" % (output, e.strerror)
            events, share, output = None, None, None
    return FileResult(path, events, share, time.perf_counter() - start, output, error), warned


# The private hooks of CPython's warnings module that a per-thread capture needs (Debian 12's 3.11 has them).
_PER_THREAD_WARNINGS = hasattr(warnings, "_showwarnmsg") and hasattr(warnings, "_filters_mutated")
_capture_lock = threading.Lock()
_capture = {"tasks": 0, "show": None, "always": None}
_capture_thread = threading.local()


def _show_or_keep(message):
    """warnings._showwarnmsg while a task runs in this process: the warnings of
    a task's thread kept in its list, every other thread's shown as before."""
    log = getattr(_capture_thread, "log", None)
    if log is not None:
        log.append(message)
    else:
        _capture["show"](message)


@contextlib.contextmanager
def _warnings_of_this_thread():
    """The warnings this thread issues meanwhile, every one (an "always"
    filter), in the list it yields. Not warnings.catch_warnings, which patches
    the process's warnings module for the whole block: two tasks' blocks that
    overlapped on threads of one process (a worker of several threads, a
    LocalCluster(processes=False) in the caller's process) swapped their
    warnings, and the one left last restored the other's recorder, which
    then took every later warning of the process, unseen. Here the first task
    in installs the process's hook and the last one out removes it."""
    if not _PER_THREAD_WARNINGS:  # a Python without these hooks: the process's, as before
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield caught
        return
    log = []
    with _capture_lock:
        if _capture["tasks"] == 0:
            _capture["show"] = warnings._showwarnmsg
            _capture["always"] = ("always", None, Warning, None, 0)
            warnings._showwarnmsg = _show_or_keep
            warnings.filters.insert(0, _capture["always"])
            warnings._filters_mutated()
        _capture["tasks"] += 1
    _capture_thread.log = log
    try:
        yield log
    finally:
        _capture_thread.log = None
        with _capture_lock:
            _capture["tasks"] -= 1
            if _capture["tasks"] == 0:
                if warnings._showwarnmsg is _show_or_keep:
                    warnings._showwarnmsg = _capture["show"]
                for k, f in enumerate(warnings.filters):
                    if f is _capture["always"]:
                        del warnings.filters[k]
                        break
                warnings._filters_mutated()


@contextlib.contextmanager
def _sigint_ignored(when):
    """A second Ctrl-C must not cut the cleanup after the first short (closing
    the cluster waits seconds for its workers): SIGINT ignored meanwhile, on
    the main thread (the only one that can set a handler)."""
    if not when or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


# Dask's per-worker housekeeping, set for tasks that are one long C++ call
# each: the statistical profiler samples every worker's Python stacks each
# 10 ms (nothing to see inside process_file) and the nanny and system monitors
# poll psutil each 100 / 500 ms. On 2 cores that CPU is taken from the tasks:
# 2 workers ran 1.58-1.69x one worker with Dask's defaults, 1.78-1.91x with
# these (bench/bench_python.py [--dask-defaults], 6 files, idle machine).
LOCAL_WORKER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
}


def local_cluster(workers=2):
    """A distributed.LocalCluster for evlife tasks on this machine: `workers`
    processes of one thread each, Dask's housekeeping slowed down
    (LOCAL_WORKER_CONFIG). process_files makes one when no scheduler is given;
    make it yourself to reuse it across calls: process_files(..., scheduler=cluster)."""
    _check_main_guard()
    _check_workers(workers, None)  # none would leave every task waiting
    import dask
    from distributed import LocalCluster
    with dask.config.set(LOCAL_WORKER_CONFIG):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=":0", loop=_shared_loop())


_loop_runner = None
_loop_lock = threading.Lock()


def _forget_loop_in_child():
    # A forked child has the runner but not its thread: it makes its own.
    global _loop_runner, _loop_lock
    _loop_runner = None
    _loop_lock = threading.Lock()


os.register_at_fork(after_in_child=_forget_loop_in_child)


def _shared_loop():
    """One event loop (in a thread of its own) for every cluster and client this
    module makes: Dask's own loop per synchronous cluster or client is never
    closed (this Dask, 2022.12: 3 descriptors, an epoll and a socket pair, per
    process_files call, until the process ran out of them)."""
    global _loop_runner
    with _loop_lock:
        if _loop_runner is None:
            from distributed.utils import LoopRunner
            runner = LoopRunner(asynchronous=False)
            runner.start()
            _loop_runner = runner
        return _loop_runner.loop


def _main_module_reimported():
    """The main module as multiprocessing's spawn (Dask's default start method
    for its workers; forkserver too) runs it again in every new process: its
    file, "<stdin>" for a script read from standard input, or None where
    nothing runs again (fork, interactive sessions, notebooks, python -c, a
    package's __main__ run with -m)."""
    import dask
    if dask.config.get("distributed.worker.multiprocessing-method", "spawn") == "fork":
        return None
    main = sys.modules.get("__main__")
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if name is not None and (name == "__main__" or name.endswith(".__main__")):
        return None  # multiprocessing's _fixup_main_from_name skips these
    path = getattr(main, "__file__", None)
    if path == "<stdin>":
        return path
    if path is None or not os.path.isfile(path):
        return None
    return os.path.realpath(path)


def _is_main_guard(node):
    """True for an `if`, `while`, `match`, conditional expression (`main() if
    __name__ == "__main__" else None`) or `and`/`or` (`__name__ == "__main__"
    and main()`) that tests __name__ against "__main__" in any form (==, in a
    tuple, a case pattern): leniently, as a false refusal is worse than a
    missed one."""
    import ast
    if isinstance(node, (ast.If, ast.While, ast.IfExp)):
        parts = [node.test]
    elif isinstance(node, ast.BoolOp):
        parts = node.values
    elif isinstance(node, getattr(ast, "Match", ())):
        parts = [node.subject] + [c.pattern for c in node.cases]
    else:
        return False
    names = constants = False
    for part in parts:
        for n in ast.walk(part):
            names = names or (isinstance(n, ast.Name) and n.id == "__name__")
            constants = constants or (isinstance(n, ast.Constant) and n.value == "__main__")
    return names and constants


def _unguarded_call_site(script):
    """(file, line) of the top-level statement of `script` (the main script,
    a real path) that this call comes from, when no `if __name__ ==
    "__main__":` encloses it; else None."""
    import ast
    import inspect
    top = None
    frame = inspect.currentframe()
    while frame is not None:
        code = frame.f_code
        if code.co_name == "<module>" and os.path.realpath(code.co_filename) == script:
            top = frame
        frame = frame.f_back
    if top is None:
        return None
    line = top.f_lineno
    try:
        with open(script, encoding="utf-8") as f:
            source = f.read()
        tree = ast.parse(source, script)
        running = compile(source, script, "exec")
    except (OSError, SyntaxError, ValueError, UnicodeDecodeError):
        return None  # cannot tell: no false alarm
    if running.co_code != top.f_code.co_code or \
            list(running.co_lines()) != list(top.f_code.co_lines()):
        return None  # the file changed since the script started: its lines are not the running ones
    for node in ast.walk(tree):
        if node is not tree and hasattr(node, "lineno") and \
                node.lineno <= line <= (node.end_lineno or node.lineno) and _is_main_guard(node):
            return None
    return script, line


def _check_main_guard():
    script = _main_module_reimported()
    if script is None:
        return
    if script == "<stdin>":
        raise RuntimeError(
            "a script read from standard input cannot start a Dask LocalCluster: its worker "
            "processes would import <stdin> again and be restarted for ever. Save the script "
            "to a file, or pass scheduler= the address of a running scheduler.")
    site = _unguarded_call_site(script)
    if site is not None:
        raise RuntimeError(
            '%s:%d starts a Dask LocalCluster outside `if __name__ == "__main__":`. Its worker '
            "processes import the script again and would each start a cluster of their own, "
            "for ever. Put the call under that guard (see help(evlife.batch)), or pass "
            "scheduler= the address of a running scheduler." % site)


def _check_workers(workers, scheduler):
    # LocalCluster(n_workers=0) starts no worker: the tasks would wait for ever.
    if scheduler is not None:
        return
    try:
        count = operator.index(workers)
    except TypeError:
        count = 0
    if isinstance(workers, bool) or count < 1:
        raise ValueError("workers must be a whole number of at least 1 (the LocalCluster's processes), got %r"
                         % (workers,))


@contextlib.contextmanager
def _sigint_deferred():
    """Ctrl-C while our LocalCluster starts (a second or more) is recorded, not
    raised in the middle of its start: a half-started cluster cannot be closed
    (it printed an AssertionError at exit). Yields a list, non-empty once
    pressed; main thread only (elsewhere no signal arrives)."""
    pressed = []
    # Off the main thread no signal arrives; a caller that ignores SIGINT (a job
    # started with `&` by a script) keeps ignoring it: its workers, spawned
    # meanwhile, inherit SIG_IGN (a handler of ours they reset to the default,
    # and a Ctrl-C to the process group killed them: the batch waited for ever).
    if threading.current_thread() is not threading.main_thread() or signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        yield pressed
        return
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        yield pressed
    finally:
        signal.signal(signal.SIGINT, previous)


def _client(scheduler, workers):
    """(client, things to close). scheduler: None, an address, a Client or a
    cluster. KeyboardInterrupt for a Ctrl-C while our own cluster started,
    raised once it is closed again."""
    from distributed import Client
    if scheduler is None:
        with _sigint_deferred() as pressed:
            cluster = local_cluster(workers)
            client = Client(cluster, loop=_shared_loop())
        if pressed:
            with _sigint_ignored(True):
                client.close()
                cluster.close()
            raise KeyboardInterrupt
        return client, [client, cluster]
    if isinstance(scheduler, Client):
        return scheduler, []
    if isinstance(scheduler, str):  # an address ("tcp://host:8786")
        client = Client(scheduler, loop=_shared_loop())
    else:  # a cluster object: its own loop
        client = Client(scheduler)
    return client, [client]


def _batch_function(function):
    """`function` (process_files, process_slices) as called by the user, in one frame (its
    warnings, at stacklevel 3, stay at the caller's line):
    a call that does not fit its signature said as evlife's functions say it (_arguments.checking:
    Python's "process_files() missing 2 required positional arguments" named no evlife.batch, nor
    the required argument a keyword misspelt);
    a configuration that is a pipe (config="/dev/stdin", <(...), a FIFO) read from a copy of it in
    $TMPDIR, removed when it returns: its check of the options and then every task opened it
    again, found it empty, and the defaults stood, silently."""
    checked = checking(function, "batch." + function.__name__)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with checked(args, kwargs):
            if kwargs.get("config") is None:
                return function(*args, **kwargs)
            with _streams.readable(kwargs["config"]) as copy:
                return function(*args, **dict(kwargs, config=copy))
    return wrapper


def _own_keywords(function):
    """The named parameters of `function` (through _batch_function to the function's own signature):
    a misspelling of one is said so, not taken for an estimator key. Not the required ones: the call
    gave them (outdir= beside out_dir= is no misspelling of it)."""
    return tuple(name for name, parameter in inspect.signature(function).parameters.items()
                 if parameter.kind is not parameter.VAR_KEYWORD and parameter.default is not parameter.empty)


@_batch_function
def process_files(paths, out_dir, scheduler=None, *, workers=2, sensor=None, config=None,
                  extension=".bin", progress=True, one_thread=True, from_s=None, to_s=None,
                  topic=None, time_unit=None, polarity=None, **options):
    """Process many recordings on Dask distributed, one task per recording.

    paths: recordings (any format of `evlife process`).
    out_dir: created if needed; each result is written there as
    NAME.bin (or `extension`: ".csv", ".h5"), NAME from the recording's file
    name (made unique), the same bytes as `evlife process PATH -o OUT`.
    scheduler: None = a LocalCluster of `workers` processes on this machine
    (one thread each), or a scheduler address ("tcp://host:8786"), a
    distributed.Client or a cluster object.
    sensor, config, from_s, to_s, topic, time_unit, polarity, **options: as
    evlife.process (every estimator keyword); checked here before any task
    starts (ValueError / TypeError). topic: the same ROS topic (or HDF5
    camera, .npz array) in every file; time_unit: of every CSV/NumPy file.
    one_thread: True (the default) runs each recording on its worker's one
    thread: with one worker per core, reading ahead and writing behind would
    only compete with the other workers' estimators.
    progress: a line per finished recording on stderr, and one whenever
    none has finished for STILL_RUNNING_EVERY_S (30 s): how long, and the
    outputs being written with their sizes (where this process sees them).

    Returns a BatchResult: one FileResult row (path, events, lifetime_share,
    seconds, output, error) per path, in order. A failed recording is reported
    by name in its row (and in .failed; events: those written before an input
    fault, else None; output: None where no file was written); the others are
    not affected. Events a task's estimator rejected (labelled noise) and
    records of the format it skipped, which the command line's summary
    counts, are RuntimeWarnings naming the recording, at the caller's line
    (as every task's warnings, once every row is in). Each task writes out_dir/.evlife-partial-RUN.NAME and
    renames it NAME when it ends (a task whose worker died, which Dask gave
    up on with KilledWorker: its partial file removed, its row's error says
    so). Ctrl-C raises evlife.Interrupted whose
    .partial is the BatchResult: the finished rows (their warnings issued), and a row per unfinished
    recording saying nothing was written (its partial file removed on the
    LocalCluster made here, whose workers stop; on a cluster of yours a task
    still running removes its partial file when it ends, and a queued one never
    starts: a Dask Event, "evlife-batch-stop-RUN", left set on your scheduler)
    or that its task ended meanwhile; no file of out_dir is left cut, nor
    replaced but by a whole output, nor written after the call.
    """
    if isinstance(paths, (str, bytes, os.PathLike)):  # its characters are no recordings
        raise TypeError("paths: a list of recordings, not one path (process_files([%r], ...))" % (paths,))
    paths = [os.fsdecode(p) for p in paths]
    out_dir = os.fsdecode(out_dir)
    _check_workers(workers, scheduler)
    # Bad options fail now, with the command line's message, not once per task; named as this
    # function's (a misspelled workers= or extension= was "evlife.LifetimeEstimator() got an
    # unexpected keyword argument ...: unknown configuration key 'estimator.worker'").
    _evlife._check_options("evlife.batch.process_files", _own_keywords(process_files), config=config, **options)
    _evlife.LifetimeEstimator(sensor=(1, 1), config=config, **options)
    if sensor is not None:
        _evlife._check_sensor(sensor)  # not LifetimeEstimator(sensor): 1.4 GB for the largest
    _evlife._check_str("evlife.batch.process_files", "extension", extension)
    _evlife._check_bool("evlife.batch.process_files", "one_thread", one_thread)
    _evlife._check_bool("evlife.batch.process_files", "progress", progress)
    if extension.lower() not in OUTPUT_EXTENSIONS:
        raise ValueError("extension: %r is none of %s" % (extension, ", ".join(OUTPUT_EXTENSIONS)))
    _evlife._check_reader_options(from_s, to_s, time_unit, polarity, where="evlife.batch.process_files")
    _check_topic(topic)
    crop = {k: v for k, v in (("from_s", from_s), ("to_s", to_s), ("topic", topic), ("time_unit", time_unit),
                              ("polarity", polarity)) if v is not None}
    os.makedirs(out_dir, exist_ok=True)
    outputs = [os.path.join(os.path.abspath(out_dir), n) for n in _output_names(paths, extension, out_dir)]
    if not paths:
        return BatchResult()
    from distributed import KilledWorker, as_completed
    run = uuid.uuid4().hex[:8]  # a fresh key per call: Dask must not reuse older results
    stop = "evlife-batch-stop-" + run  # set when the call gives up on its tasks: _give_up
    before = [_identity(out) for out in outputs]  # an unfinished task's output, replaced meanwhile?
    try:
        client, to_close = _client(scheduler, workers)
    except KeyboardInterrupt:  # no task was submitted, to any cluster: every row is "nothing written"
        raise _interrupted([None] * len(paths), paths, outputs, run, before, True) from None
    interrupted = False
    futures, index, rows, task_warnings = [], {}, [None] * len(paths), []
    try:
        still_running = _StillRunning(
            progress, lambda: "%d/%d done" % (sum(r is not None for r in rows), len(rows)),
            lambda: [(os.path.basename(outputs[i]), _partial_name(outputs[i], run))
                     for i, r in enumerate(rows) if r is None])
        try:
            # Largest recordings first (Dask runs higher priority first): the
            # last task to finish is then a small one, so workers end together.
            # Inside the try: a Ctrl-C while thousands are submitted gives up on
            # those submitted (they ran on and wrote after the call raised).
            for i, (p, out) in enumerate(zip(paths, outputs)):
                futures.append(client.submit(_process_one, os.path.abspath(p), out, run, sensor, config, one_thread,
                                             crop, dict(options), stop, pure=False, priority=_size_or_zero(p),
                                             key="evlife-%s-%d-%s" % (run, i, _key_text(os.path.basename(p)))))
                index[futures[-1].key] = i
            with still_running:
                for done, future in enumerate(as_completed(futures), 1):
                    i = index[future.key]
                    try:
                        row, warned = future.result()
                        row = row._replace(path=paths[i])
                        if row.error == _NOTHING_WRITTEN:  # not given up on: its worker lost the scheduler (_stopped)
                            row = row._replace(error="its worker could not reach the scheduler; nothing written")
                        task_warnings += warned
                        # Its events when counted (None: a failure that counted none), its time in the worker.
                        figures = ("" if row.events is None else "%d events, " % row.events) + "%.2f s" % row.seconds
                    except Exception as e:  # the worker died, the scheduler went away: still reported by name
                        # Dask gave up on the task (KilledWorker): its partial output,
                        # cut where the worker died, is removed where this process sees it.
                        with contextlib.suppress(OSError):
                            _streams._remove(_partial_name(outputs[i], run))
                        lost = _scheduler_lost(client, e)
                        row = FileResult(paths[i], None, None, math.nan, None,
                                         "%s (nothing written; its partial output, if any, was removed)"
                                         % (lost or "%s: %s" % (type(e).__name__, e)))
                        # No figure is known: what happened instead.
                        figures = "failed: " + ("worker killed" if isinstance(e, KilledWorker) else
                                                "scheduler lost" if lost else type(e).__name__)
                    rows[i] = row
                    status = "ok" if row.error is None else "FAILED: " + _first_line(row.error)
                    still_running.finished("evlife.batch: %d/%d %s (%s) %s" % (
                        done, len(futures), paths[i], figures, status))
        except KeyboardInterrupt:
            interrupted = True
            with _sigint_ignored(True):
                _give_up(client, stop, futures)
                for f in futures:  # finished before the cancel: their rows, as if waited for
                    i = index[f.key]
                    if rows[i] is None and f.status == "finished":
                        row, warned = f.result()
                        if row.error == _NOTHING_WRITTEN:  # it saw the call give up: unfinished
                            continue
                        rows[i] = row._replace(path=paths[i])
                        task_warnings += warned
        else:
            # After every row (a filter making them errors cuts no task short);
            # stacklevel 3: the caller's line, past _batch_function.
            for text, category in task_warnings:
                warnings.warn(text, category, stacklevel=3)
            return BatchResult(rows)
    finally:
        with _sigint_ignored(interrupted):
            for c in to_close:  # a cluster of our own: its workers stop (a task cut short)
                c.close()
    error = _interrupted(rows, paths, outputs, run, before, own_cluster=scheduler is None)
    # The finished rows' warnings, as after a whole batch (they were dropped);
    # one that a filter makes an error does not take the interruption's place.
    for text, category in task_warnings:
        with contextlib.suppress(Warning):
            warnings.warn(text, category, stacklevel=3)
    raise error


def _scheduler_lost(client, error):
    """What to say of a task's `error` where Dask cancelled it because the
    client lost its scheduler (a crash, a network cut; the row said only
    "CancelledError: evlife-KEY"), else None."""
    from distributed import CancelledError
    if not isinstance(error, CancelledError) or client.status == "running":
        return None
    return "lost the connection to the scheduler %s (CancelledError)" % getattr(client.scheduler, "address", "")


def _key_text(name):
    """A file name as Dask's messages (msgpack, UTF-8) can carry it in a task key:
    a name that is not UTF-8 (b"caf\\xe9.mat", its lone surrogate after
    os.fsdecode) with its bytes as \\xNN (the surrogate broke the connection,
    every task cancelled)."""
    return os.fsencode(name).decode("utf-8", "backslashreplace")


def _identity(path):
    """What tells a file from the one of its name before (None: no file)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_ino, st.st_mtime_ns, st.st_size)


def _interrupted(rows, paths, outputs, run, before, own_cluster):
    """evlife.Interrupted for Ctrl-C during process_files: the finished rows
    kept in .partial. An unfinished task wrote to its partial name only
    (_partial_name: a file cut short by the stop would read as a shorter
    recording, a .bin cut at a 4 KiB page holding whole records): removed
    where its worker was stopped; on a cluster not ours a task still running
    removes it when it ends (_give_up). A task that ended after this call
    stopped waiting (its worker's last seconds) renamed its output: said so
    (where this process sees the workers' files), its figures unknown."""
    unfinished = [i for i, r in enumerate(rows) if r is None]
    for i in unfinished:
        output = None
        if _identity(outputs[i]) != before[i]:
            what, output = "interrupted; its task ended meanwhile and wrote its output (its figures not known)", outputs[i]
        elif own_cluster:
            _streams._remove(_partial_name(outputs[i], run))
            what = _NOTHING_WRITTEN + " (its partial output, if any, was removed)"
        else:
            what = _NOTHING_WRITTEN + " (a task still running on your cluster removes its partial output when it ends)"
        rows[i] = FileResult(paths[i], None, None, math.nan, output, what)
    finished = len(rows) - len(unfinished)
    error = _evlife.Interrupted("evlife.batch.process_files: interrupted; %d of %d recordings finished "
                                "(their rows in .partial)" % (finished, len(rows)))
    error.partial = BatchResult(rows)
    error.events_processed = sum(r.events or 0 for r in rows if r.error is None)
    error.events_written = None
    return error


def _check_topic(topic):
    if topic is not None and (not isinstance(topic, str) or not topic):
        raise ValueError("topic: a ROS topic or an HDF5 file's camera, got %r" % (topic,))


def _slice_task(path, part, sensor, t_begin, t_end, warmup_us, config, topic, time_unit, options, stop):
    """The task of one slice: its augmented events written to `part` (.bin) as
    they are estimated (constant memory, however long the slice). `stop`: the
    name of the call's Dask Event, set once the call gave up on its slices
    (_give_up): then no part is written, or the one written is removed."""
    from evlife import _evlife as core
    if _stopped(stop):  # queued when the call gave up: Dask's cancel may reach the worker after it starts
        return None
    start = time.perf_counter()
    r = core._process_time_range(path, part, sensor, t_begin, t_end, warmup_us, config=config,
                                 topic=topic, time_unit=time_unit, **options)
    if _stopped(stop):  # checked once the part is whole: see _give_up
        with contextlib.suppress(FileNotFoundError):
            os.remove(part)
        return None
    return r["events"], r["with_lifetime"], time.perf_counter() - start, r["rejected"]


_BIN_HEADER_BYTES = 32  # the .bin format (README): a 32-byte header, then the records


def _join_parts(output, parts):
    """One header, then every slice's records in order, into `output`."""
    try:
        with open(output, "wb") as out:
            for k, part in enumerate(parts):
                with open(part, "rb") as f:
                    if k > 0:
                        f.seek(_BIN_HEADER_BYTES)
                    shutil.copyfileobj(f, out, 1 << 20)
    except OSError as e:
        raise OSError(e.errno, "%s: cannot join the slices' part files into it: %s" % (
            output, e.strerror or e)) from e
    for part in parts:
        os.remove(part)


@_batch_function
def process_slices(path, output, slices=2, warmup_ms=100.0, scheduler=None, *, workers=2,
                   sensor=None, config=None, progress=True, topic=None, time_unit=None, **options):
    """One long recording cut into `slices` equal time slices processed in parallel.

    Each slice's estimator starts `warmup_ms` before its slice (those events
    only build up its state; their outputs are dropped), so the result is
    close to, not identical with, one pass: an event whose window or
    prediction reaches back further than the warm-up can differ (README:
    measured share). With warmup_ms at least the recording's length the result
    is identical. Writes `output` (.bin, the format of `evlife process`) with
    the slices in order; returns a BatchResult with one row per slice
    (path "PATH[k]"). scheduler, workers, sensor, config, topic, time_unit, **options: as
    process_files. progress: a line per slice on stderr, in order, and the
    slices' part files written while none finishes (as process_files). Raises on failure (the slices are one result: no part file
    stays, nor a partial output); then, and on Ctrl-C, the slices not yet
    running never start, on a cluster of yours too, and one still running there
    removes its part when it ends (a Dask Event, "evlife-slices-stop-RUN", left set
    on your scheduler). Rejected events and skipped non-event
    records are warned of as evlife.process warns (RuntimeWarning), each counted once.
    When it raises, nothing is warned of, as evlife.process when it raises (process_files
    warns of its finished rows, whose outputs stay): the counts are of the one result,
    which is not written: the skipped records are the whole file's (from its scan, not a
    slice's), and the events a finished slice rejected were in a part file removed with it.
    """
    path = os.path.abspath(os.fsdecode(path))
    output = os.path.abspath(os.fsdecode(output))  # the parts are written where the workers run
    _check_workers(workers, scheduler)
    # slices=2.5 raised range()'s "'float' object cannot be interpreted as an integer"; True made one slice.
    try:
        count = operator.index(slices)
    except TypeError:
        count = 0
    if isinstance(slices, bool) or count < 1:
        raise ValueError("slices must be a whole number of at least 1, got %r" % (slices,))
    slices = count
    parts = ["%s.part%d.bin" % (output, k) for k in range(slices)]
    for target in [output] + parts:  # the rule of process_file and the CLI, theirs
        _evlife._refuse_overwriting_input(path, target)
    if not output.endswith(".bin"):
        raise ValueError("process_slices writes a .bin file: %s" % output)
    if not 0.0 <= float(warmup_ms) < float("inf"):  # NaN too; checked here, not once per worker
        raise ValueError("warmup_ms must be a finite number of milliseconds >= 0, got %r" % (warmup_ms,))
    _evlife._check_bool("evlife.batch.process_slices", "progress", progress)
    _evlife._check_options("evlife.batch.process_slices", _own_keywords(process_slices), config=config, **options)
    _evlife.LifetimeEstimator(sensor=(1, 1), config=config, **options)  # bad options: now
    _check_topic(topic)
    _evlife._check_reader_options(time_unit=time_unit, where="evlife.batch.process_slices")
    info = _evlife.scan(path, sensor, config=config, topic=topic, time_unit=time_unit)
    t0, t1 = info["t_first"], info["t_last"] + 1
    cuts = [t0 + (t1 - t0) * k // slices for k in range(slices)] + [t1]
    # Beyond 2^62 us (146,000 years) every warm-up is the whole recording: int64 for the workers.
    warmup_us = min(int(round(warmup_ms * 1000.0)), 1 << 62)
    from distributed import wait
    client, to_close = _client(scheduler, workers)
    futures, joining, gave_up = [], False, False
    run = uuid.uuid4().hex[:8]
    stop = "evlife-slices-stop-" + run  # set when the call gives up on its slices: _give_up
    try:
        # The last slice has no end: t_last + 1 is past int64 for an event at INT64_MAX.
        for k in range(slices):  # appended one by one: a Ctrl-C meanwhile gives up on those submitted
            futures.append(client.submit(_slice_task, path, parts[k], info["sensor"], cuts[k],
                                         cuts[k + 1] if k + 1 < slices else None,
                                         warmup_us, config, topic, time_unit, dict(options), stop, pure=False,
                                         key="evlife-slice-%s-%d-%s" % (run, k, _key_text(os.path.basename(path)))))
        rows, rejected = [], Counter()
        still_running = _StillRunning(
            progress, lambda: "%d/%d slices of %s done" % (sum(f.done() for f in futures), slices, path),
            lambda: [(os.path.basename(parts[k]), parts[k]) for k, f in enumerate(futures) if not f.done()])
        with still_running:
            for k, f in enumerate(futures):
                try:
                    result = f.result()
                except Exception as e:
                    lost = _scheduler_lost(client, e)
                    if lost is None:
                        raise
                    raise RuntimeError("evlife.batch.process_slices: %s: slice %d: %s" % (path, k, lost)) from e
                if result is None:  # not given up on: its worker lost the scheduler (_stopped)
                    raise RuntimeError("evlife.batch.process_slices: %s: slice %d wrote nothing: its worker could "
                                       "not reach the scheduler" % (path, k))
                events, with_lifetime, seconds, slice_rejected = result
                rejected.update(slice_rejected)  # adds the counts
                rows.append(FileResult("%s[%d]" % (path, k), events,
                                       with_lifetime / events if events else 0.0, seconds, output, None))
                still_running.finished("evlife.batch: slice %d/%d of %s (%d events, %.2f s)" % (
                    k + 1, slices, path, events, seconds))
        wait(futures)
        joining = True
        _join_parts(output, parts)
    except BaseException:
        # The slices are one result: no part file, nor a partial output, stays
        # (an output that was there before is kept unless the join began).
        gave_up = True
        # The slices not yet running never start (on a cluster of yours they ran on after a Ctrl-C,
        # each writing its part file after the removal); the running ones remove theirs. Also with
        # no future: a Ctrl-C inside the first submit may leave its slice queued.
        with _sigint_ignored(True), contextlib.suppress(Exception):  # a scheduler gone: nothing runs
            _give_up(client, stop, futures)
        raise
    finally:
        with _sigint_ignored(gave_up):
            for c in to_close:  # a cluster of our own: its workers stop, a slice cut short in its part
                c.close()
            # After the close: a slice of our own cluster stopped between its creating its part and its check.
            for leftover in (parts + ([output] if joining else [])) if gave_up else []:
                with contextlib.suppress(OSError):
                    os.remove(leftover)
    # As evlife.process warns of what it dropped: the events the slices rejected, each in its own
    # time range; the records of the format that are no events, from the scan (a slice's reader
    # also counts those before its range, which it skips or drops).
    for text in _evlife._dropped_warnings("evlife.batch.process_slices", path, dict(info, rejected=dict(rejected))):
        warnings.warn(text, RuntimeWarning, stacklevel=3)
    return BatchResult(rows)
