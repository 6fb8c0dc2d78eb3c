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
) -> Dict[str, Any]: ...
