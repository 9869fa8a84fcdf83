"""One self-contained HTML page over every image check of a run, and every failing vertex check's picture.

Guarantees: the page needs nothing but itself (pictures are embedded as base64 ``data:`` URIs read
from the PNGs :mod:`.artefacts` wrote; no external stylesheet, script, font or image), every string
taken from a record is escaped with :func:`html.escape` (record data never reaches the script), and
the file appears complete or not at all. Failed checks come first. The filters (a text filter over
scene, kind, sync, message and test id; checkboxes for failed/passed and for each kind) are plain
inline JavaScript; with JavaScript off they stay hidden and every check is shown.

Order: failed checks first, then passes whose physics verdict differs, then passes; within each, by
kind, scene and frame. What a card shows, from the record: its verdict, message, metrics against
limits (``≥`` for names in :data:`AT_LEAST_PREFIXES`, else ``≤``), pictures, params, sync,
reproduce command, and from ``details``: ``verdicts`` (a golden's sync and renderer verdicts, a chip
each with its tolerance set: :mod:`.reftest`), ``diagnosis`` (the known mistake a failure's drawing is, in
its own line under the message), ``tolerance_set`` (the tolerance set in force), ``physics``
(a golden's second verdict, on the stored physics state, shown beside the picture verdicts: the dict of
``snapshots.PhysicsVerdict.as_dict()``, or a bool, or a string such as ``"pass"``), and a "chaotic"
note when ``details["physics"]["chaotic"]`` or ``details["chaotic"]`` is true or the frame is past
``details["chaotic_after"]``. Other details are listed under "details": lists of rows (per-target
numbers) as tables, the rest as JSON.
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
from pathlib import Path
from typing import Any, Iterable

from conformance.files import write_atomically
from conformance.reports.artefacts import ROLES, _jsonable
from conformance.rendering.records import KINDS, ImageCheck

__all__ = ["render_report", "write_report"]

#: Metric names held to a lower bound (``iou`` ≥ limit); every other limit is an upper bound.
AT_LEAST_PREFIXES = ("iou", "min_", "smallest_", "coverage")

_LABELS = {"expected": "expected (golden)", "actual": "actual (the sync's render)",
           "difference": "sync verdict: render vs live reference",
           "reference": "live reference (reference sync, this renderer)",
           "reference_difference": "renderer verdict: live reference vs golden",
           "pybullet_mask": "pyBullet mask", "fury_mask": "FURY mask", "mask_difference": "mask difference",
           "outlined": "the sync's drawing, with the outline of where pyBullet has each failing body"}
# The colours silhouettes.mask_images uses; shown under the picture so it can be read without the code.
_LEGENDS = {"mask_difference": (("#fff", "both"), ("#f00", "only FURY"), ("#00f", "only pyBullet"),
                                ("#ff0", "different targets")),
            "outlined": (("#f0f", "pyBullet's outline"),)}
_SHOWN_DETAILS = ("tolerance_set", "physics", "chaotic", "chaotic_after", "diagnosis", "verdicts")
#: At most this many rows of a table in "details" (a pile has hundreds of targets).
MAX_ROWS = 200


def _e(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _fmt(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _at_least(name: str) -> bool:
    return name.startswith(AT_LEAST_PREFIXES) or name.endswith("_iou")


def _verdict(value: Any) -> tuple[str, str]:
    """A physics verdict in whatever form a check stored it, as (``pass``/``fail``/``warn``/``info``, text).

    ``snapshots.PhysicsVerdict.as_dict()`` is the usual form: ``ok``, ``chaotic``, and the largest
    ``position`` and ``angle`` difference at ``target`` with their tolerances. A difference past the
    scene's chaotic step is a warning, not a failure (another platform may legitimately differ there).
    """
    if isinstance(value, bool):
        return ("pass" if value else "fail"), ("pass" if value else "differs")
    if isinstance(value, dict):
        passed = value.get("passed", value.get("ok"))
        state = "info" if passed is None else "pass" if passed else "warn" if value.get("chaotic") else "fail"
        text = str(value.get("message") or value.get("verdict") or "")
        if not text and "position" in value:
            where = f" at {value['target']!r}" if value.get("target") else ""
            text = (f"{'pass' if passed else 'differs'}{where}: {_fmt(value['position'])} m"
                    f" (tolerance {_fmt(value.get('position_tolerance'))} m), {_fmt(value.get('angle'))} rad"
                    f" (tolerance {_fmt(value.get('angle_tolerance'))} rad)")
        return state, text or {"pass": "pass", "fail": "differs", "warn": "differs", "info": "?"}[state]
    text = str(value)
    head = text.strip().lower()
    state = "pass" if head.startswith(("pass", "ok", "match")) else "fail" if head.startswith(("fail", "differ", "mismatch")) else "info"
    return state, text


def _physics_state(record: ImageCheck) -> str | None:
    return _verdict(record.details["physics"])[0] if "physics" in record.details else None


def _chaotic(record: ImageCheck) -> int | bool | None:
    """Whether the frame is past the scene's chaotic step: the step when known, else True, else None."""
    after = record.details.get("chaotic_after")
    if isinstance(after, int) and not isinstance(after, bool) and record.frame > after:
        return after
    physics = record.details.get("physics")
    return bool(record.details.get("chaotic") or (isinstance(physics, dict) and physics.get("chaotic"))) or None


def _order(record: ImageCheck):
    rank = 0 if not record.passed else 1 if _physics_state(record) in ("fail", "warn") else 2
    kind = KINDS.index(record.kind) if record.kind in KINDS else len(KINDS)
    return rank, kind, record.scene, record.frame, record.sync, record.nodeid


def _picture(results_dir: Path, role: str, relative: str) -> str:
    caption = _e(_LABELS.get(role, role))
    path = (results_dir / relative).resolve()
    try:
        # Only pictures inside the results directory: a records file must not pull other files into a page.
        path.relative_to(results_dir.resolve())
        data = path.read_bytes()
    except (OSError, ValueError):
        return f'<figure class="missing"><div>picture missing:<br><code>{_e(relative)}</code></div><figcaption>{caption}</figcaption></figure>'
    uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
    legend = "".join(f'<span class="key"><i style="background:{colour}"></i>{_e(text)}</span>'
                     for colour, text in _LEGENDS.get(role, ()))
    return (f'<figure title="click to enlarge"><img src="{uri}" alt="{caption}" loading="lazy">'
            f"<figcaption>{caption}{'<br>' + legend if legend else ''}</figcaption></figure>")


def _metrics(record: ImageCheck) -> str:
    names = list(record.metrics) + [name for name in record.limits if name not in record.metrics]
    if not names:
        return ""
    rows = []
    for name in names:
        value, limit = record.metrics.get(name), record.limits.get(name)
        bound, state = "", ""
        if limit is not None:
            sign = "≥" if _at_least(name) else "≤"
            bound = f"{sign} {_fmt(limit)}"
            if isinstance(value, (int, float)) and isinstance(limit, (int, float)) and not math.isnan(value):
                within = value >= limit if sign == "≥" else value <= limit
                state = "pass" if within else "fail"
        mark = {"pass": "✓", "fail": "✗"}.get(state, "")
        rows.append(f'<tr class="{state}"><th>{_e(name)}</th><td>{_e(_fmt(value) if value is not None else "–")}</td>'
                    f"<td>{_e(bound)}</td><td class=mark>{mark}</td></tr>")
    return '<table class="metrics"><tr><th>metric</th><th>measured</th><th>limit</th><th></th></tr>' + "".join(rows) + "</table>"


def _chips(record: ImageCheck) -> str:
    chips = []
    verdicts = record.details.get("verdicts")
    if isinstance(verdicts, dict):
        # A golden's picture verdicts, apart: what the sync did (against the live reference) and what
        # the renderer did (the live reference against the golden).
        for name, verdict in verdicts.items():
            if isinstance(verdict, dict):
                state = "pass" if verdict.get("passed") else "fail"
                chips.append(f'<span class="chip {state}" title="{_e(verdict.get("message", ""))}; set '
                             f'{_e(verdict.get("tolerance_set", ""))}: {_e(verdict.get("why", ""))}">'
                             f'{_e(name)} verdict: {state} ({_e(verdict.get("tolerance_set", ""))})</span>')
    if "physics" in record.details:
        # A golden has two verdicts: the picture (the record's) and the stored physics state's.
        if not isinstance(verdicts, dict):
            render = "pass" if record.passed else "fail"
            chips.append(f'<span class="chip {render}">render: {render}</span>')
        state, text = _verdict(record.details["physics"])
        chips.append(f'<span class="chip {state}" title="{_e(text)}">physics: {_e(text)}</span>')
    chaotic = _chaotic(record)
    if chaotic:
        after = "" if chaotic is True else f" (after step {chaotic})"
        chips.append(f'<span class="chip warn" title="small platform differences in floating point grow here; '
                     f'the stored physics state may not be reproduced on another machine">chaotic{_e(after)}</span>')
    if record.details.get("tolerance_set") and not isinstance(verdicts, dict):
        chips.append(f'<span class="chip">tolerance set: {_e(record.details["tolerance_set"])}</span>')
    if record.sync:
        chips.append(f'<span class="chip">sync: {_e(record.sync)}</span>')
    for key, value in record.params.items():
        chips.append(f'<span class="chip param">{_e(key)}={_e(json.dumps(value, default=_jsonable))}</span>')
    return '<div class="chips">' + "".join(chips) + "</div>"


def _compact(value: Any) -> str:
    if isinstance(value, float):
        return _fmt(value)
    if isinstance(value, (list, tuple)) and all(isinstance(v, (int, float)) for v in value):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    if isinstance(value, str):
        return value
    return json.dumps(value, default=_jsonable, ensure_ascii=False)


def _details(extra: dict[str, Any], nodeid: str) -> str:
    """The rest of ``details``: lists of rows (per-target numbers) as tables, anything else as JSON."""
    parts = [f"<p>test: <code>{_e(nodeid)}</code></p>"] if nodeid else []
    rest = {}
    for key, value in extra.items():
        if isinstance(value, list) and value and all(isinstance(row, dict) for row in value):
            columns = list(dict.fromkeys(k for row in value for k in row))
            head = "".join(f"<th>{_e(c)}</th>" for c in columns)
            rows = "".join("<tr>" + "".join(f"<td>{_e(_compact(row.get(c, '')))}</td>" for c in columns) + "</tr>"
                           for row in value[:MAX_ROWS])
            more = f"<p>… and {len(value) - MAX_ROWS} more rows</p>" if len(value) > MAX_ROWS else ""
            parts.append(f'<p>{_e(key)}</p><table class="rows"><tr>{head}</tr>{rows}</table>{more}')
        else:
            rest[key] = value
    if rest:
        body = json.dumps(rest, indent=1, sort_keys=True, default=_jsonable, ensure_ascii=False)
        parts.append(f"<pre>{_e(body)}</pre>")
    return f"<details><summary>details</summary>{''.join(parts)}</details>"


def _card(record: ImageCheck, index: int, results_dir: Path) -> str:
    status = "passed" if record.passed else "failed"
    physics = _physics_state(record)
    roles = list(ROLES.get(record.kind, ())) + [r for r in record.images if r not in ROLES.get(record.kind, ())]
    pictures = "".join(_picture(results_dir, role, record.images[role]) for role in roles if role in record.images)
    params = " ".join(f"{k}={v}" for k, v in record.params.items())
    text = " ".join([record.kind, record.scene, record.sync, record.message, record.nodeid, params, status]).lower()
    extra = {k: v for k, v in record.details.items() if k not in _SHOWN_DETAILS}
    parts = [
        f'<article class="card {status}{" physics-" + physics if physics else ""}" id="check-{index}" '
        f'data-status="{status}" data-kind="{_e(record.kind)}" data-text="{_e(text)}">',
        f'<h2><span class="badge">{"FAIL" if not record.passed else "PASS"}</span> '
        f'<span class="kind">{_e(record.kind)}</span> <b>{_e(record.scene)}</b> '
        f'<span class="frame">frame {_e(record.frame)}</span><a class="anchor" href="#check-{index}">#</a></h2>',
        _chips(record),
    ]
    if record.message:
        parts.append(f'<pre class="message">{_e(record.message)}</pre>')
    if record.details.get("diagnosis"):
        parts.append(f'<p class="diagnosis"><b>diagnosis</b> {_e(record.details["diagnosis"])}</p>')
    if pictures:
        parts.append(f'<div class="pictures">{pictures}</div>')
    parts.append(_metrics(record))
    if record.reproduce:
        parts.append(f'<div class="repro"><span>reproduce</span><code>{_e(record.reproduce)}</code></div>')
    if extra or record.nodeid:
        parts.append(_details(extra, record.nodeid))
    parts.append("</article>")
    return "\n".join(p for p in parts if p)


def render_report(records: Iterable[ImageCheck], results_dir: str | os.PathLike, *,
                  title: str = "Image checks", header_lines: Iterable[str] = ()) -> str:
    """The page as a string (see the module docstring for what it guarantees)."""
    results_dir = Path(results_dir)
    ordered = sorted(records, key=_order)
    failed = sum(not r.passed for r in ordered)
    kinds = [k for k in KINDS if any(r.kind == k for r in ordered)] + sorted({r.kind for r in ordered} - set(KINDS))
    per_kind = ", ".join(f"{k} {sum(r.kind == k for r in ordered)}"
                         + (f" ({n} failed)" if (n := sum(r.kind == k and not r.passed for r in ordered)) else "")
                         for k in kinds)
    summary = (f'<span class="count">{len(ordered)} check{"s" if len(ordered) != 1 else ""} with pictures</span>, '
               f'<span class="{"bad" if failed else "good"}">{failed} failed</span>, {len(ordered) - failed} passed'
               + (f' <span class="kinds">· {_e(per_kind)}</span>' if per_kind else ""))
    header = "".join(f"<li>{_e(line)}</li>" for line in header_lines)
    boxes = [("status", "failed", "failed"), ("status", "passed", "passed")] + [("kind", k, k) for k in kinds]
    filters = "".join(f'<label><input type="checkbox" checked data-group="{g}" value="{_e(v)}"> {_e(label)}</label>'
                      for g, v, label in boxes)
    cards = "\n".join(_card(record, i, results_dir) for i, record in enumerate(ordered, start=1))
    empty = "" if ordered else '<p class="empty">No checks with pictures were recorded in this run.</p>'
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{_e(title)}</title><style>{_CSS}</style></head>
<body><header><h1>{_e(title)}</h1><p class="summary">{summary}</p>
<ul class="meta">{header}</ul></header>
<nav id="filters" hidden><input type="search" placeholder="filter: scene, kind, sync, message…" aria-label="filter">
{filters}<span id="shown"></span></nav>
<main>{empty}
{cards}
</main><script>{_JS}</script></body></html>
"""


def write_report(records: Iterable[ImageCheck], results_dir: str | os.PathLike, *, title: str = "Image checks",
                 header_lines: Iterable[str] = (), filename: str = "report.html") -> Path:
    """Write the page to ``results_dir/filename`` atomically and return its path."""
    results_dir = Path(results_dir)
    page = render_report(records, results_dir, title=title, header_lines=header_lines)
    return write_atomically(results_dir / filename, page.encode("utf-8"))


_CSS = """
:root{--fail:#c62828;--pass:#2e7d32;--warn:#b26a00;--ink:#1d232b;--muted:#5f6b7a;--line:#dde2e8;--bg:#f4f6f8}
*{box-sizing:border-box}[hidden]{display:none!important}
body{margin:0;background:var(--bg);color:var(--ink);font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif}
header{background:#fff;padding:16px 24px 2px}
h1{margin:0 0 4px;font-size:20px}
.summary{margin:0 0 6px;font-size:15px}.summary .bad{color:var(--fail);font-weight:600}.summary .good{color:var(--pass);font-weight:600}
.kinds{color:var(--muted)}
.meta{margin:0 0 8px;padding:0;list-style:none;color:var(--muted);font:12px/1.5 ui-monospace,"DejaVu Sans Mono",monospace}
#filters{display:flex;flex-wrap:wrap;gap:6px 14px;align-items:center;padding:6px 24px 10px;background:#fff;border-bottom:1px solid var(--line);position:sticky;top:0;z-index:1}
#filters input[type=search]{flex:0 1 320px;padding:5px 8px;border:1px solid var(--line);border-radius:6px;font:inherit}
#filters label{cursor:pointer;user-select:none}#shown{color:var(--muted);margin-left:auto}
main{padding:16px 24px;display:flex;flex-direction:column;gap:14px}
.card{background:#fff;border:1px solid var(--line);border-left:5px solid var(--pass);border-radius:8px;padding:12px 16px}
.card.failed{border-left-color:var(--fail)}.card.passed.physics-fail,.card.passed.physics-warn{border-left-color:var(--warn)}
.card h2{margin:0 0 6px;font-size:16px;font-weight:500;display:flex;gap:8px;align-items:baseline}
.badge{font-size:11px;font-weight:700;letter-spacing:.05em;color:#fff;background:var(--pass);border-radius:4px;padding:1px 6px}
.failed .badge{background:var(--fail)}
.kind{color:var(--muted);text-transform:uppercase;font-size:12px;letter-spacing:.04em}.frame{color:var(--muted)}
.anchor{margin-left:auto;color:var(--line);text-decoration:none}.anchor:hover{color:var(--muted)}
.chips{display:flex;flex-wrap:wrap;gap:5px;margin-bottom:6px}
.chip{font-size:12px;border:1px solid var(--line);border-radius:999px;padding:1px 9px;color:var(--muted);max-width:100%;overflow:hidden;text-overflow:ellipsis;white-space:nowrap}
.chip.pass{color:var(--pass);border-color:#a5d6a7;background:#f1f8f1}.chip.fail{color:var(--fail);border-color:#ef9a9a;background:#fdf1f1}
.chip.warn{color:var(--warn);border-color:#ffcc80;background:#fff8ec}.chip.param{font-family:ui-monospace,"DejaVu Sans Mono",monospace}
.message{margin:4px 0 10px;padding:8px 10px;background:#fdf1f1;border-radius:6px;white-space:pre-wrap;word-break:break-word;font:12.5px/1.45 ui-monospace,"DejaVu Sans Mono",monospace}
.passed .message{background:#f5f7f9}
.diagnosis{margin:-4px 0 10px;padding:6px 10px;border-left:3px solid var(--warn);background:#fff8ec;font-size:13px}
.pictures{display:flex;flex-wrap:wrap;gap:10px;margin:6px 0 10px}
figure{margin:0;cursor:zoom-in;flex:0 1 385px;min-width:240px}figure.zoom{flex-basis:100%;cursor:zoom-out}
figure img{display:block;width:100%;height:auto;border:1px solid var(--line);border-radius:4px;image-rendering:pixelated;background:#000}
figcaption{font-size:12px;color:var(--muted);text-align:center;margin-top:3px}
figure.missing div{aspect-ratio:450/384;display:flex;align-items:center;justify-content:center;text-align:center;border:1px dashed var(--line);border-radius:4px;color:var(--muted)}
.metrics{border-collapse:collapse;font-size:13px;margin:2px 0 8px}
.metrics th,.metrics td{padding:2px 12px 2px 0;text-align:left;font-variant-numeric:tabular-nums}
.metrics tr:first-child th{color:var(--muted);font-weight:500;border-bottom:1px solid var(--line)}
.metrics td:nth-child(2),.metrics td:nth-child(3){text-align:right;font-family:ui-monospace,"DejaVu Sans Mono",monospace}
.metrics tr.fail td{color:var(--fail);font-weight:600}.metrics tr.pass .mark{color:var(--pass)}
.repro{display:flex;gap:8px;align-items:center;margin:4px 0}.repro span{color:var(--muted);font-size:12px}
.repro code{flex:1;user-select:all;background:#1d232b;color:#e8eef4;padding:6px 10px;border-radius:6px;overflow-x:auto;white-space:pre;font:12.5px ui-monospace,"DejaVu Sans Mono",monospace}
.repro button{font:12px inherit;padding:4px 10px;border:1px solid var(--line);border-radius:6px;background:#fff;cursor:pointer}
details{margin-top:4px;font-size:12.5px}summary{cursor:pointer;color:var(--muted)}
details pre{background:#f5f7f9;padding:8px;border-radius:6px;overflow-x:auto;margin:4px 0}
details p{margin:6px 0 2px;color:var(--muted)}
.rows{border-collapse:collapse;font:12px ui-monospace,"DejaVu Sans Mono",monospace}
.rows th,.rows td{border-bottom:1px solid var(--line);padding:2px 10px 2px 0;text-align:left;white-space:nowrap}
.rows th{color:var(--muted);font-weight:500}
.key{display:inline-flex;align-items:center;gap:3px;margin:0 5px}.key i{width:9px;height:9px;border:1px solid #999;display:inline-block}
.empty{color:var(--muted)}
"""

# Static: no record data is ever interpolated into the script, so escaping the HTML is enough.
_JS = """
(function(){
  var box=document.getElementById('filters'); box.hidden=false;
  var search=box.querySelector('input[type=search]'), checks=box.querySelectorAll('input[type=checkbox]');
  var cards=document.querySelectorAll('article.card'), shown=document.getElementById('shown');
  function apply(){
    var on={}; checks.forEach(function(c){on[c.dataset.group+':'+c.value]=c.checked;});
    var words=search.value.toLowerCase().split(/\\s+/).filter(Boolean), n=0;
    cards.forEach(function(card){
      var ok=on['status:'+card.dataset.status]!==false&&on['kind:'+card.dataset.kind]!==false&&
        words.every(function(w){return card.dataset.text.indexOf(w)>=0;});
      card.hidden=!ok; if(ok)n++;
    });
    shown.textContent='showing '+n+' of '+cards.length;
  }
  search.addEventListener('input',apply); checks.forEach(function(c){c.addEventListener('change',apply);});
  document.querySelectorAll('.repro code').forEach(function(code){
    var b=document.createElement('button'); b.type='button'; b.textContent='copy';
    b.addEventListener('click',function(){
      var done=function(){b.textContent='copied'; setTimeout(function(){b.textContent='copy';},1200);};
      if(navigator.clipboard){navigator.clipboard.writeText(code.textContent).then(done,function(){});}
      else{var r=document.createRange(); r.selectNodeContents(code); var s=getSelection(); s.removeAllRanges(); s.addRange(r); document.execCommand('copy'); done();}
    });
    code.parentNode.appendChild(b);
  });
  document.querySelectorAll('.pictures figure').forEach(function(f){
    f.addEventListener('click',function(){f.classList.toggle('zoom');});
  });
  apply();
})();
"""
