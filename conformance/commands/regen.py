"""``regen [SCENE…] [--missing | --failing]``: make golden snapshots anew and say what changed: per
golden new, changed (both written), unchanged, or kept (only float noise in its state differed).
``regen --prune``: delete the files of the golden directories that no check reads, and make nothing."""

from __future__ import annotations

from pathlib import Path

from conformance import validation

NAME = "regen"
HELP = "make golden snapshots anew (reference sync), atomically; print what changed"


def add_arguments(parser) -> None:
    parser.add_argument("scene", nargs="*", help="scene names (default: every scene)")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--missing", action="store_true", help="only goldens that are missing or unreadable")
    which.add_argument("--failing", action="store_true", help="only goldens that are missing, unreadable or fail "
                       "the render check with the reference sync")
    which.add_argument("--prune", action="store_true", help="make nothing: delete the files in the golden directories "
                       "that no check reads (scenes removed or renamed, frames no longer golden, stray files)")
    parser.add_argument("--golden-dir", default=None, help="directory of goldens for every scene named (default: each scene's own: the kit's, or golden/<backend>/ beside your scene file)")


def run(args, extra) -> int:
    from conformance import scenes
    from conformance.sync import own_scenes
    from conformance.backends.display import virtual_display
    from conformance.progress import progress
    from conformance.rendering import snapshots

    names = args.scene or scenes.names()
    for name in names:
        scenes.get(name)  # an unknown name fails before anything is rendered or written
    given = validation.directory_to_write("--golden-dir", args.golden_dir) if args.golden_dir is not None else None
    directories = {name: given if given is not None else own_scenes.golden_dir(name) for name in names}
    if args.prune:
        return _prune(given, set(directories.values()))
    mode = "missing" if args.missing else "failing" if args.failing else "all"
    counts = {"new": 0, "changed": 0, "unchanged": 0, "kept": 0}
    with virtual_display():
        for name in progress(names, total=len(names), what="goldens"):  # a bar on a terminal only
            for change in snapshots.regenerate(name, directories[name], mode=mode):
                counts[change.status] += 1
                print(change.describe())
    where = ", ".join(str(d) for d in dict.fromkeys(directories.values()))
    print(f"goldens in {where}: {counts['new']} new, {counts['changed']} changed, {counts['unchanged']} unchanged, "
          f"{counts['kept']} kept with float noise"
          + ("" if mode == "all" else f" (only {mode} ones were made)"))
    return 0


def _prune(given, directories: set) -> int:
    """Delete :func:`conformance.rendering.golden.stale` files of each of ``directories``, then its emptied
    folders. What a directory must keep is every registered scene's goldens there, not only the scenes
    named: ``regen --prune chain`` prunes chain's directory and never deletes another scene's goldens."""
    from conformance.sync import own_scenes
    from conformance.rendering import golden

    stale = golden.stale_by_directory(lambda name: given if given is not None else own_scenes.golden_dir(name))
    chosen = {Path(d) for d in directories}
    deleted = 0
    for directory in chosen:
        for path in stale.get(directory, []):
            path.unlink()
            deleted += 1
            print(f"deleted {path}")
        for folder in sorted((p for p in directory.rglob("*") if p.is_dir()), key=lambda p: len(p.parts), reverse=True):
            if not any(folder.iterdir()):
                folder.rmdir()
    where = ", ".join(str(d) for d in chosen)
    print(f"goldens in {where}: {deleted} file(s) no check reads deleted")
    return 0
