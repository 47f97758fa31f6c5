"""Named pipes and sockets as input (`<(zcat x.txt.gz)`, `/dev/stdin` in a pipeline).

evlife's readers read a file's start again once they know its format, and
several formats need the file's size, so a stream is first copied into a
temporary file (in $TMPDIR, else /tmp), as the command line does with `-` and
pipes. The copy keeps the pipe's extension (formats told by it: .dat, .bag)
and is removed when the call returns; for evlife.open, when its StreamReader
is closed or garbage-collected. InputErrors, Interrupted and the
RuntimeWarnings of a call name the stream, not the copy.
"""
import builtins
import contextlib
import functools
import os
import stat
import tempfile
import weakref

from . import _evlife
from ._arguments import checking, public

_CHUNK_BYTES = 1 << 20
_DOC_NOTE = ("\n\nA named pipe or socket (<(zcat x.txt.gz), /dev/stdin in a pipeline) is first copied into a temporary file "
             "in $TMPDIR, removed when done; errors name the pipe.")


def is_stream(path):
    """True for a path (str, bytes or os.PathLike) that is a named pipe or a socket."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        return False
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False  # the reader's own error names what is wrong
    return stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode)


def _open_stream(name):
    """The stream as a binary file: a pipe by its name; a socket, which no
    open() reads, by the descriptor it names (/dev/stdin, /dev/fd/N,
    /proc/self/fd/N) or else by connecting to it (a listening socket file)."""
    if not stat.S_ISSOCK(os.stat(name).st_mode):
        return builtins.open(name, "rb", buffering=0)
    descriptor = {"/dev/stdin": 0}.get(name)
    for prefix in ("/dev/fd/", "/proc/self/fd/"):
        if name.startswith(prefix) and name[len(prefix):].isdigit():
            descriptor = int(name[len(prefix):])
    if descriptor is not None:
        return os.fdopen(os.dup(descriptor), "rb", buffering=0)
    import socket
    connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        connection.connect(name)
    except OSError:
        connection.close()
        raise
    return connection.makefile("rb", buffering=0)


def _copy(stream):
    """Copies the stream into a new temporary file; returns its path. An
    OSError names the stream (and the copy, for a write that failed)."""
    name = os.fsdecode(os.fspath(stream))
    extension = os.path.splitext(name)[1]
    fd, copy = tempfile.mkstemp(prefix="evlife-stream-", suffix=extension if len(extension) <= 8 else "")
    copied = 0
    try:
        with _open_stream(name) as source:
            while True:
                try:
                    chunk = source.read(_CHUNK_BYTES)
                except OSError as e:
                    raise OSError(e.errno, "%s: read failed after %d bytes: %s" % (name, copied, e.strerror)) from e
                if not chunk:
                    return copy
                try:
                    view = memoryview(chunk)
                    while view:
                        view = view[os.write(fd, view):]
                except OSError as e:
                    raise OSError(e.errno, "%s: cannot copy the stream into %s after %d bytes: %s; set TMPDIR "
                                  "to a folder with room, or save it to a file" % (name, copy, copied, e.strerror)
                                  ) from e
                copied += len(chunk)
    except BaseException:
        _remove(copy)
        raise
    finally:
        os.close(fd)


def _named_after(error, stream, copy):
    """The InputError `error` of the copy, told of the stream instead."""
    name = os.fsdecode(os.fspath(stream))
    if getattr(error, "path", None) == copy:
        error.path = name
    error.args = tuple(a.replace(copy, name) if isinstance(a, str) else a for a in error.args)
    return error


def _remove(path):
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


@contextlib.contextmanager
def readable(path):
    """`path` itself, or for a stream the path of a temporary copy (removed on exit)."""
    if not is_stream(path):
        yield path
        return
    copy = _copy(path)
    try:
        yield copy
    except (_evlife.InputError, _evlife.Interrupted) as e:
        raise _named_after(e, path, copy)
    finally:
        _remove(copy)


class _PathArgument:
    """Where a function takes its path: by keyword `name` or at `position`."""

    def __init__(self, name, position=0):
        self.name, self.position = name, position

    def given(self, args, kwargs):
        return self.name in kwargs or len(args) > self.position

    def of(self, args, kwargs):
        return kwargs[self.name] if self.name in kwargs else args[self.position]

    def replaced(self, args, kwargs, path):
        if self.name in kwargs:
            return args, {**kwargs, self.name: path}
        return args[:self.position] + (path,) + args[self.position + 1:], kwargs


def reading_streams(function, argument, output=None):
    """`function` (a C++ function of the module) taking a stream as its path
    argument `argument` (its keyword; the first positional argument), and
    writing to its argument `output` (keyword; the second positional), if any:
    checked against the stream itself before the copy is made (against the
    copy, a pipe as both passed, and the output's open waited for a reader)."""
    where = _PathArgument(argument)
    written = _PathArgument(output, 1) if output else None
    checked = checking(function)  # a call that does not fit its signature, said as Python says it

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with checked(args, kwargs):
            if not where.given(args, kwargs):
                return function(*args, **kwargs)  # its own error
            if written and written.given(args, kwargs) and is_stream(where.of(args, kwargs)):
                _evlife._refuse_overwriting_input(where.of(args, kwargs), written.of(args, kwargs))
            stream = where.of(args, kwargs)
            with readable(stream) as source:
                args, kwargs = where.replaced(args, kwargs, source)
                if source is stream:
                    return function(*args, **kwargs)
                # The call's warnings name the pipe, not its copy (per thread, in C++:
                # warnings.catch_warnings would catch every thread's).
                _evlife._stream_alias(source, os.fsdecode(os.fspath(stream)))
                try:
                    return function(*args, **kwargs)
                finally:
                    _evlife._stream_alias("", "")
    wrapper.__doc__ = (function.__doc__ or "") + _DOC_NOTE
    return public(wrapper)


# A call of Reader.read that does not fit its signature, said as Python says it (pybind11 named
# nothing). A context around Reader._read, which warns 2 frames up: in a one-frame wrapper (reader_read,
# StreamReader.read) its warnings stay at the line that called read.
checked_read = checking(_evlife.Reader._read, "Reader.read")


@functools.wraps(_evlife.Reader.read)
def reader_read(self, *args, **kwargs):
    with checked_read((self,) + args, kwargs):
        return self._read(*args, **kwargs)


reader_read = public(reader_read, "Reader.read")


class StreamReader:
    """What evlife.open returns for a stream: the Reader of its temporary copy,
    with the same properties and methods, but `path` and the InputErrors of
    its reads name the stream; close() (or the end of a `with`, or garbage
    collection) removes the copy."""

    def __init__(self, reader, stream, copy):
        self._reader = reader
        self._stream = stream
        self._copy = copy
        self._remove_copy = weakref.finalize(self, _remove, copy)

    def __getattr__(self, name):
        return getattr(self._reader, name)

    # isinstance(r, evlife.Reader) holds for a stream's reader as for a file's
    # (isinstance consults __class__ where type() is not a subclass).
    @property
    def __class__(self):
        return type(self._reader)

    @property
    def path(self):
        return os.fsdecode(os.fspath(self._stream))

    @contextlib.contextmanager
    def _naming_the_stream(self):
        # Its warnings (a crop that selected nothing) name the pipe too, at the caller's line.
        _evlife._stream_alias(self._copy, self.path)
        try:
            yield
        except _evlife.InputError as e:
            raise _named_after(e, self._stream, self._copy)
        finally:
            _evlife._stream_alias("", "")

    def read(self, *args, **kwargs):
        with self._naming_the_stream(), checked_read((self._reader,) + args, kwargs):
            return self._reader._read(*args, **kwargs)

    def __iter__(self):
        return self

    def __next__(self):
        with self._naming_the_stream():
            return self._reader._next()

    def close(self):
        self._reader.close()
        self._remove_copy()

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()


def open_reading_streams(function):
    """evlife.open taking a stream: a StreamReader of its copy."""
    where = _PathArgument("path")
    checked = checking(function)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with checked(args, kwargs):
            if not where.given(args, kwargs) or not is_stream(where.of(args, kwargs)):
                return function(*args, **kwargs)
            stream = where.of(args, kwargs)
            copy = _copy(stream)
            args, kwargs = where.replaced(args, kwargs, copy)
            try:
                reader = function(*args, **kwargs)
            except _evlife.InputError as e:
                _remove(copy)
                raise _named_after(e, stream, copy)
            except BaseException:
                _remove(copy)
                raise
            return StreamReader(reader, stream, copy)
    wrapper.__doc__ = (function.__doc__ or "") + _DOC_NOTE
    return public(wrapper)
