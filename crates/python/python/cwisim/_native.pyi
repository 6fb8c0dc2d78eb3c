"""Type stubs of cwisim's native module (crates/python/src/lib.rs). Use the `cwisim`
package's functions: they wrap these."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

class CwisimError(Exception):
    """Anything cwisim refuses or fails at; the message says what and where."""

class SceneError(CwisimError):
    """A scene that cannot be read: the message locates it."""

class UsageError(CwisimError):
    """An unknown name, settings that do not go together, or a size over a limit."""

def scenes() -> List[Tuple[str, str]]: ...
def scene_text(name: str) -> str: ...
def renderers() -> List[Tuple[str, str, List[str]]]: ...
def setting_names() -> List[str]: ...
def render(
    scene: Optional[str] = None,
    scene_json: Optional[str] = None,
    name: str = "scene",
    renderer: str = "vanrij",
    settings: Sequence[Tuple[str, str]] = (),
    numeric: str = "f64",
    timing: str = "fast",
    machine: Optional[str] = None,
    threads: int = 1,
    progress: Optional[Any] = None,
) -> Dict[str, Any]: ...
def opcodes() -> List[Tuple[int, str]]: ...
def emit_stream(
    scene: Optional[str] = None,
    scene_json: Optional[str] = None,
    name: str = "scene",
    renderer: str = "vanrij",
    settings: Sequence[Tuple[str, str]] = (),
    threads: int = 1,
) -> Dict[str, Any]: ...
def read_trace(path: str) -> Dict[str, Any]: ...
def encode_trace(
    width: int,
    lines: int,
    channels: int,
    code: Any,
    x: Any,
    dx: Any,
    values: Any,
    note: Any,
    notes: Sequence[str],
    encoding: str,
) -> bytes: ...
def replay(
    path: str, numeric: str = "f64", timing: str = "fast", machine: Optional[str] = None
) -> Dict[str, Any]: ...
def default_formats() -> List[str]: ...
def default_tessellations() -> List[int]: ...
def pareto(points: Sequence[Tuple[int, int, float]]) -> List[bool]: ...
def keyword_spelling(message: str) -> str: ...

class TradeoffPlan:
    def __init__(
        self,
        scene: Optional[str] = None,
        size: Optional[str] = None,
        tessellate: Sequence[int] = (),
        shadows: Sequence[bool] = (),
        renderers: Sequence[str] = (),
        numeric: Sequence[str] = (),
        machine: Optional[str] = None,
    ) -> None: ...
    def groups(self) -> int: ...
    def settings(self) -> int: ...
    def skipped(self) -> List[Tuple[str, str]]: ...
    def measure(self, g: int, repeat: int = 3) -> str: ...
def fit(
    scene: Optional[str] = None,
    renderer: str = "vanrij",
    settings: Sequence[Tuple[str, str]] = (),
    max_error: float = ...,
    overflow: str = "saturate",
    machine: Optional[str] = None,
    threads: int = 0,
) -> Dict[str, Any]: ...
def refine(
    scene: Optional[str] = None,
    phases: str = "flat,gouraud,phong,aa",
    settings: Sequence[Tuple[str, str]] = (),
    machine: Optional[str] = None,
    threads: int = 1,
) -> Dict[str, Any]: ...
def history(
    path: str, x: int, line: int, numeric: str = "f64", machine: Optional[str] = None
) -> List[Dict[str, Any]]: ...
def trace_header(path: str) -> Tuple[int, int, int]: ...
def waveform(
    path: str,
    line: int,
    first: int,
    last: int,
    numeric: str = "f64",
    machine: Optional[str] = None,
) -> Dict[str, Any]: ...
