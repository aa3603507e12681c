"""The calibration report: one self-contained HTML page (inline CSS, figures as base64 PNG; no script, no link).

:func:`render` turns :func:`zerocal_sym.report.contents.report_contents` into
the page.  Sections (their ``id``): ``verdict``, ``offsets``, ``error-budget``,
``fit-check``, ``residuals``, ``robot``, ``accuracy``.  Every number taken
from the results file or computed from it is written in a cell or span with
its full value in ``data-value`` (Python's ``repr``), shown rounded; a
section without its data says what is missing (``not in this result file``,
``give --data``).
"""
from __future__ import annotations

import base64
import html
import math
import struct

import numpy as np

#: the page's style sheet (inline)
CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 1.5em auto; max-width: 72em;
       padding: 0 1em; color: #1b1b1b; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { font-size: 1.25em; border-bottom: 1px solid #ccc;
     padding-bottom: 0.15em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0; } th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; }
th { background: #f2f2f2; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
.meta { color: #555; font-size: 0.92em; } .verdict { font-size: 1.08em; padding: 0.6em 0.9em; border-radius: 4px; }
.ok { background: #e7f5e7; border: 1px solid #7cb87c; } .bad { background: #fbe9e9; border: 1px solid #d08080; }
.missing { color: #8a6d00; font-style: italic; } img { max-width: 100%; height: auto; display: block;
           margin: 0.5em 0; } code { background: #f4f4f4; padding: 0 0.2em; } details { margin: 0.5em 0; }
"""


#: what a result's 1 sigma includes (its ``std_kind``), in words
STD_KINDS = {"total": "total (the noise through the model; for TSVD also its linearisation and truncation bias)",
             "from residuals": "from the residuals (no noise model: the noise level estimated from them)",
             "lower bound": "a lower bound (a known contribution could not be evaluated)"}


def esc(text) -> str:
    return html.escape(str(text), quote=True)


def num(value, fmt: str = ".4g", unit: str = "", tag: str = "td") -> str:
    """A number with its full value in ``data-value``; NaN / None shown as ``n/a``."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return f'<{tag} class="num" data-value="nan">n/a</{tag}>'
    v = float(value)
    shown = format(v, fmt) + (f" {unit}" if unit else "")
    cls = ' class="num"' if tag == "td" else ""
    return f'<{tag}{cls} data-value="{v!r}">{esc(shown)}</{tag}>'


def missing(text: str) -> str:
    return f'<p class="missing">{esc(text)}</p>'


def image(png: bytes, alt: str) -> str:
    """An ``<img>`` of PNG bytes (data URI) with its pixel size."""
    width, height = struct.unpack(">II", png[16:24])  # the IHDR chunk
    data = base64.b64encode(png).decode("ascii")
    return f'<img alt="{esc(alt)}" width="{width}" height="{height}" src="data:image/png;base64,{data}">'


def table(header, rows) -> str:
    """``rows``: lists of cells already rendered (``<td>``...)."""
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    return f"<table><tr>{head}</tr>" + "".join(f"<tr>{''.join(r)}</tr>" for r in rows) + "</table>"


def _section(sid: str, title: str, body: str) -> str:
    return f'<section id="{sid}"><h2>{esc(title)}</h2>\n{body}\n</section>\n'


def _verdict(c) -> str:
    cls = "ok" if c["accepted"] else "bad"
    return f'<p class="verdict {cls}">{esc(c["verdict"])}</p>'


def _offsets(c) -> str:
    u = c["unit"]
    if not c["accepted"]:
        return missing("not reported: the result is rejected (see the verdict and the fit check)")
    rows = [[f"<td>{esc(o['name'])}</td>", num(o["value"], "+.6f"), num(o["std"], ".4g")] for o in c["offsets"]]
    body = table(["joint", f"zero offset [{u}]", f"1 sigma [{u}]"], rows)
    kind = c["result"]["std_kind"]
    body += (f"<p>1 sigma: {esc(STD_KINDS.get(kind, kind or 'as the result file states'))}.  Compensation: the "
             f"controller subtracts the offset, <code>cmd = IK(P) - offset_{esc(u)}</code> (the actual joint = "
             "commanded + offset).</p>")
    if c["maemm"]:
        rows = [[f"<td>{esc(m['name'])}</td>", num(m["value"], "+.4f"), num(m["std"], ".4g")] for m in c["maemm"]]
        body += "<p>The measuring mechanism's assembly error (MAEMM):</p>" + table(["", "value [mm]", "1 sigma [mm]"],
                                                                                   rows)
    return body


def _budget(c) -> str:
    b, u = c["error_budget"], c["unit"]
    if b is None:
        body = missing("error budget: not in this result file")
    else:
        rows = [[f"<td>{esc(e['name'])}</td>", num(e["noise_std"]), num(e["robot_file_bias"]),
                 f"<td>{esc(', '.join(e['dominant_entries']) or '-')}</td>"] for e in b["entries"]]
        body = table(["offset", f"noise 1 sigma [{u}]", f"robot-file bias [{u}]", "dominant robot-file entries"],
                     rows) if rows else missing("error budget entries: not in this result file")
        lim = b["limited_by"]
        body += (f'<p>Limited by: <strong data-value="{esc(lim)}">{esc(lim)}</strong>.</p>' if lim else
                 missing("limited_by: not in this result file"))
    bias = c["bias"]
    if bias is not None:
        rows = [[f"<td>{esc(o['name'])}</td>", num(w), num(r)]
                for o, w, r in zip(c["offsets"], bias["worst_case"], bias["rms"])]
        body += ("<p>Bias the offsets may carry from the source errors left out of the identification (first order, "
                 "at their tolerances):</p>" + table(["offset", f"worst case [{bias['unit']}]", f"RMS [{bias['unit']}]"],
                                                     rows))
    return body


def _fit(c, fig_png) -> str:
    fit = c["fit"]
    if fit is None:
        return missing("fit check: not in this result file")
    checked = fit.get("checked")
    if checked:
        decision = "rejected" if fit.get("rejected") else (
            "accepted despite misfit" if fit.get("accepted_despite_misfit") else "accepted")
    else:
        decision = f"not checked ({fit.get('reason') or 'no spare degree of freedom'})"
    body = (f"<p>chi2 {num(fit.get('chi2'), '.4g', tag='span')} on {num(fit.get('dof'), 'g', tag='span')} degrees "
            f"of freedom, p-value {num(fit.get('p_value'), '.3g', tag='span')} against the significance level "
            f"{num(fit.get('alpha'), 'g', tag='span')}: <strong>{esc(decision)}</strong>.</p>")
    m = fit.get("max_reading")
    if m is not None and m.get("rejected") and m.get("pose") is not None:
        body += (f'<p id="max-reading">The largest standardised residual, '
                 f"{num(m.get('standardised'), '+.3f', tag='span')} at <strong>pose {m['pose']:g}</strong>, has "
                 f"p-value {num(m.get('p_value'), '.3g', tag='span')} for the largest of "
                 f"{num(m.get('readings'), 'g', tag='span')} readings: below the significance level, the data "
                 "contradict the noise model at that reading whatever the chi2 says.</p>")
    w = fit.get("worst")
    if w is not None and w.get("pose") is not None:
        frm = "?" if w.get("from_pose") is None else f"{w['from_pose']:g}"
        body += (f'<p id="worst-reading">The worst reading: <strong>pose {w["pose"]:g}</strong> (the change '
                 f"from pose {esc(frm)}), standardised residual "
                 f"{num(w.get('standardised'), '+.3f', tag='span')}, its estimated error "
                 f"{num(w.get('estimated_error_mm'), '+.4g', 'mm', tag='span')}.</p>")
    if fit.get("diagnosis"):
        body += f"<p>{esc(fit['diagnosis'])}</p>"
    for warning in fit.get("warnings") or []:
        body += f'<p class="missing">{esc(warning)}</p>'
    if fig_png is not None:
        body += image(fig_png, "standardised residual per reading")
    return body


def _residuals(c, fig_png) -> str:
    r = c["residuals"]
    if r is None:
        return missing("residuals: not in this result file")
    body = (f"<p>Measured minus predicted change per reading at the {esc(r['method'])} estimate: RMS "
            f"{num(r['rms_after_mm'] * 1e3, '.3g', 'um', tag='span')}")
    if r["before_mm"] is None:
        body += ".</p>" + missing("the nominal model's residuals and the poses: give --data (the measurement file)")
    else:
        body += (f"; the nominal model's (no source errors) RMS {num(r['rms_before_mm'], '.3g', 'mm', tag='span')} "
                 f"(data: {esc(c['data_source'])}).</p>")
    return body + image(fig_png, "residuals per reading")


def _robot(c, fig_png, pose_rows) -> str:
    rb = c["robot"]
    body = (f"<p>{esc(rb['description'])}.  The workspace (grey), the robot at home (blue) and its measuring "
            "mechanism (red, dashed)")
    body += ", and the measured poses (numbered in the order measured).</p>" if c["poses"] is not None else ".</p>"
    body += image(fig_png, "the robot and its poses in the workspace")
    if pose_rows is None:
        body += missing("the measured poses: give --data (the measurement file)")
    else:
        header, V = pose_rows
        rows = [[f"<td>{k}</td>"] + [num(v, ".3f") for v in row] for k, row in enumerate(V)]
        body += f"<details><summary>the {len(V)} poses</summary>" + table(["pose"] + header, rows) + "</details>"
    return body


def _accuracy(c, fig_png) -> str:
    a = c["accuracy"]
    if a is None:
        return missing("not reported: the result is rejected")
    s = a["summary"]
    rows = [["<td>before compensation: largest |position error|</td>", num(s["max_before_mm"]),
             num(s["before_std_at_max_mm"])],
            ["<td>before compensation: mean</td>", num(s["mean_before_mm"]), "<td></td>"],
            ["<td>after compensation: largest predicted RMS error</td>", num(s["max_after_mm"]), "<td></td>"],
            ["<td>after compensation: mean predicted RMS error</td>", num(s["mean_after_mm"]), "<td></td>"]]
    o = a["orientation"]
    if o is not None:
        rows += [["<td>orientation before: largest [deg]</td>", num(o["max_before_deg"]), "<td></td>"],
                 ["<td>orientation after: largest predicted RMS [deg]</td>", num(o["max_after_deg"]), "<td></td>"]]
    body = (f"<p>The position error predicted over the workspace ({s['points']} reachable grid points) if the robot "
            "is commanded without the compensation (its zero offsets the identified ones) and with it (what the "
            "offsets' uncertainty leaves: the RMS length of the error, propagated from "
            f"{esc(c['covariance_source'])}).  Source errors outside the identified model are in neither.</p>")
    body += table(["", "value [mm]", "its 1 sigma [mm]"], rows)
    return body + (image(fig_png, "accuracy maps before and after compensation") if fig_png is not None else "")


def render(c, figs: dict, pose_rows=None, version: str = "") -> str:
    """The page (str).

    Parameters
    ----------
    c : dict
        :func:`~zerocal_sym.report.contents.report_contents`.
    figs : dict
        PNG bytes by name (``robot``, ``readings``, ``residuals``, ``accuracy``), a missing one not drawn.
    pose_rows : (list, ndarray) or None
        :func:`~zerocal_sym.report.figures.pose_table`.
    """
    rb, res = c["robot"], c["result"]
    data = f"{res['data_file']} (K = {res['K']} poses)" if res["data_file"] else "not recorded"
    meta = (f"robot <strong>{esc(rb['name'])}</strong> ({esc(rb['mechanism'])}), robot file {esc(rb['source'])}, "
            f"sha256 <code>{esc(rb['sha256'][:16])}</code>&hellip;<br>result {esc(res['source'])}: method "
            f"{esc(res['method'])}, status {esc(res['status'] or '?')}; identified from {esc(data)}")
    parts = [
        _section("verdict", "Verdict", _verdict(c)),
        _section("offsets", "Zero offsets", _offsets(c)),
        _section("error-budget", "Error budget", _budget(c)),
        _section("fit-check", "Fit check", _fit(c, figs.get("readings"))),
        _section("residuals", "Residuals", _residuals(c, figs.get("residuals")) if c["residuals"] is not None
                 else missing("residuals: not in this result file")),
        _section("robot", "The robot and its poses", _robot(c, figs["robot"], pose_rows)),
        _section("accuracy", "Accuracy over the workspace", _accuracy(c, figs.get("accuracy"))),
    ]
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
            f"<title>Calibration report: {esc(rb['name'])}</title>\n<style>{CSS}</style></head>\n<body>\n"
            f"<h1>Calibration report: {esc(rb['name'])}</h1>\n<p class=\"meta\">{meta}</p>\n" + "".join(parts)
            + f'<footer class="meta"><p>zerocal {esc(version)}</p></footer>\n</body></html>\n')


def figures_of(robot, c) -> dict:
    """The page's figures (PNG bytes) for :func:`render`."""
    from zerocal_sym.report import figures
    from zerocal_sym.report.plots import figure_residuals

    figs = {"robot": figures.png(figures.figure_robot(robot, c["poses"]))}
    if c["fit"] is not None and c["fit"].get("readings"):
        figs["readings"] = figures.png(figures.figure_readings(c["fit"]))
    if c["residuals"] is not None:
        figs["residuals"] = figures.png(figure_residuals(c["residuals"]))
    if c["accuracy"] is not None and np.isfinite(c["accuracy"]["summary"]["max_before_mm"]):
        figs["accuracy"] = figures.png(figures.figure_accuracy(c["accuracy"]))
    return figs
