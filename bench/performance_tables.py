#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Regenerates the tables of docs/PERFORMANCE.md from the benchmarks' results in bench/results:
tissue.json (bench/run.sh), tick.json (bench/tick.sh: the ticks and the materials), haptics.json (bench/haptics.sh),
soak.json (bench/soak.sh), record.json (bench/record.sh) and console.json (bench/console.sh). Each table goes between its markers <!-- begin NAME --> and
<!-- end NAME -->, with the machine and the date of the run it comes from; the prose around the
markers is left as it is. Usage: performance_tables.py [ROOT]"""
import contextlib
import io
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import summarize  # noqa: E402  (bench/summarize.py: the tissue tables)


def tissue(path):
    data = json.load(open(path))
    ctx = data["context"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        summarize.main(path)
    return f"Run of {ctx.get('date', '?')[:16]} (`bench/run.sh`), " + out.getvalue()


def tick(path):
    data = json.load(open(path))
    ctx = data["context"]
    rows = ["| scene | tets | nodes | sub-steps per tick | tick on 1 thread [us] | tick on 2 threads [us] | budget [us] "
            "| element loop, one evaluation on 1 thread [us] | the tick without it, 1 / 2 threads [us] | serial share |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    med = {b["run_name"].removesuffix("/real_time"): b for b in data["benchmarks"] if b.get("aggregate_name") == "median"}
    scenes = sorted({n.split("/")[1] for n in med if n.startswith("Tick/")})
    us = lambda b: f"{b['real_time']:.0f}" if b else "-"
    for s in scenes:
        one, two = med.get(f"Tick/{s}/threads:1"), med.get(f"Tick/{s}/threads:2")
        ref = one or two
        if not ref:
            continue
        elements, rest1, rest2 = med.get(f"Elements/{s}"), med.get(f"Serial/{s}/threads:1"), med.get(f"Serial/{s}/threads:2")
        node_work = med.get(f"NodesOnly/{s}/threads:1")
        nodes = f"{int(ref['nodes'])}" if "nodes" in ref else "-"
        # What a tick on one thread spends outside its element loops, measured directly (Serial:
        # the tick with a model that adds nothing), and of it the node work alone (NodesOnly).
        share = "-"
        if one and rest1:
            share = f"{100 * rest1['real_time'] / one['real_time']:.1f}%"
            if node_work:
                share += f" ({100 * node_work['real_time'] / one['real_time']:.1f}% node work)"
        rows.append(f"| {s} | {int(ref['tets'])} | {nodes} | {int(ref['sub_steps'])} | {us(one)} | {us(two)} | {ref['tick_budget_us']:.0f} "
                    f"| {us(elements)} | {us(rest1)} / {us(rest2)} | {share} |")
    text = f"Run of {ctx.get('date', '?')[:16]} (`bench/tick.sh`), {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, medians of 3:\n\n" + "\n".join(rows) + "\n"
    many = [med.get(f"{k}/liver-96k/chunks:16/threads:{t}") for k in ("Serial", "SerialSummedFirst") for t in (1, 2)]
    if all(many):
        text += (f"\nThe 96k tick without its element loop with 16 chunks (as on 16 threads), on 1 / 2 threads: {us(many[0])} / {us(many[1])} us "
                 f"with the buffers summed in the node update's ranges (the server's way), {us(many[2])} / {us(many[3])} us summed "
                 f"by the calling thread before it.\n")
    return text


def materials(path):
    data = json.load(open(path))
    ctx = data["context"]
    med = {b["run_name"].removesuffix("/real_time"): b for b in data["benchmarks"] if b.get("aggregate_name") == "median"}
    variants = [n.split("/")[1] for n in med if n.startswith("Material/") and n.endswith("/liver")]
    if not variants:
        return None
    rows = ["| material | liver: sub-steps | tick [us] | per sub-step [us] | x elastic | liver-12k: sub-steps | tick [us] | per sub-step [us] | x elastic |",
            "|---|---|---|---|---|---|---|---|---|"]
    per = lambda b: b["real_time"] / b["sub_steps"]
    for v in variants:
        cells = []
        for scene in ("liver", "liver-12k"):
            b, e = med.get(f"Material/{v}/{scene}"), med.get(f"Material/elastic/{scene}")
            cells += [f"{int(b['sub_steps'])}", f"{b['real_time']:.0f}", f"{per(b):.0f}", f"{per(b) / per(e):.2f}"] if b and e else ["-"] * 4
        rows.append(f"| {v} | " + " | ".join(cells) + " |")
    return (f"Run of {ctx.get('date', '?')[:16]} (`bench/tick.sh`), {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
            "medians of 3, forces on the scene's threads (liver 1, liver-12k 2):\n\n" + "\n".join(rows) + "\n")


def haptics(path):
    data = json.load(open(path))
    rows = data["rows"]
    dds = next((r for r in rows if r["kind"] == "ddsperf"), None)
    head = ["| run | mesh frames [Hz] | round trip p50 / p99 / max [us] | physics [Hz] | step p50 / p99 [us] | late ticks | missed slots | resets | client rendering [Hz] |",
            "|---|---|---|---|---|---|---|---|---|"]
    if dds:
        head.append(f"| ddsperf ping-pong, 64 B at 1 kHz (the floor) | - | {dds['p50_us']:.0f} / {dds['p99_us']:.0f} / {dds['max_us']:.0f} | - | - | - | - | - | - |")
    for r in rows:
        if r["kind"] != "viscera":
            continue
        head.append(f"| {r['scene']} ({r['tets']} tets), {r['seconds']:.0f} s pressing | {r['frames_hz']:.0f} | {r['p50_us']:.0f} / {r['p99_us']:.0f} / {r['max_us']:.0f} | "
                    f"{r['rate_hz']:.0f} | {r['step_p50_us']:.0f} / {r['step_p99_us']:.0f} | {r['late_ticks']} | {r['missed_slots']} | {r['physics_resets']} | {r['render_hz']:.0f} |")
    ratios = []
    v = [r for r in rows if r["kind"] == "viscera"]
    for off, on in zip(v[0::2], v[1::2]):
        if off["scene"] == on["scene"] and off["mesh_hz"] == 0 and on["mesh_hz"] > 0:
            ratios.append(f"{off['scene']}: p99 with 60 Hz frames / without = {on['p99_us'] / off['p99_us']:.2f}")
            if dds:
                ratios.append(f"{off['scene']}: p50 {off['p50_us']:.0f} us against 3 x ddsperf's p50 + the step's p50 = "
                              f"{3 * dds['p50_us'] + off['step_p50_us']:.0f} us")
    return (f"Run of {data['date_utc']} UTC (`bench/haptics.sh`), {data['machine']}:\n\n" + "\n".join(head) + "\n\n" +
            "".join(f"- {x}\n" for x in ratios))


def soak(path):
    r = json.load(open(path))
    s = r["series"]
    return (f"Run of {r['date_utc']} UTC (`bench/soak.sh {r['minutes']:g}`), {r['machine']}, scene {r['scene']}: {r['press_runs']} press runs, "
            f"{r['grasp_runs']} grasp runs, {r['console_requests']} console requests, failures {r['press_failed'] + r['grasp_failed'] + r['console_failed']}; "
            f"server {'alive throughout' if r['server_alive_throughout'] else 'DIED'}, exit status {r['server_exit_status']}.\n\n"
            "| | first | last | min | max | growth per hour after the warm-up | noise (RMS about the fit) |\n|---|---|---|---|---|---|---|\n"
            + "".join(f"| {name} | {s[k]['first']:.4g} | {s[k]['last']:.4g} | {s[k]['min']:.4g} | {s[k]['max']:.4g} | {s[k]['growth_per_hour']:+.3g} | {s[k]['noise_rms']:.3g} |\n"
                      for k, name in [("rss_kb", "resident memory [MB]"), ("threads", "threads"), ("fds", "file descriptors")])
            + "\n![the soak's samples](soak.svg)\n")


def record(path):
    r = json.load(open(path))
    m = r["messages"]
    lost_forces = r["forces_published"] - r["forces_recorded"]
    lost_frames = r["frames_published"] - r["frames_recorded"]
    rows = [
        "| | value |", "|---|---|",
        f"| session | {r['seconds']:g} s of a 1 kHz press on {r['scene']}, surface frames at 60 Hz; recording span {r['recording_span_s']:.0f} s |",
        f"| messages | {sum(m.values())}: commands {m.get('instrument_command', 0)}, forces {m.get('force_feedback', 0)}, frames {m.get('mesh_frame', 0)}, "
        f"telemetry {m.get('telemetry', 0)}, events {m.get('event', 0)} |",
        f"| file | {r['file_mb']:.0f} MB ({r['compression']}; {r['mb_per_minute']:.0f} MB per minute; payloads {r['payload_mb']:.0f} MB, ratio {r['compression_ratio']:.2f}) |",
        f"| recorder CPU | {r['recorder_cpu_percent_of_one_core']:.1f}% of one core |",
        f"| recorder peak memory | {r['recorder_peak_rss_mb']:.0f} MB |",
        f"| lost, by sequence numbers | {r['missing_by_sequence']} |",
        f"| forces published / recorded | {r['forces_published']} / {r['forces_recorded']} ({'all of them' if lost_forces == 0 else f'{lost_forces} not in the file'}) |",
        f"| frames published / recorded | {r['frames_published']} / {r['frames_recorded']} ({'all of them' if lost_frames == 0 else f'{lost_frames} not in the file'}) |",
        f"| the server's physics while recording | {r['physics_ticks']} ticks in {r['recording_span_s']:.0f} s ({r['physics_ticks'] / r['recording_span_s']:.0f} per second on average; the slowest second {r['physics_rate_hz_min']:.0f}) |",
    ]
    return f"Run of {r['date_utc']} UTC (`bench/record.sh {r['seconds']:g}`), {r['machine']}:\n\n" + "\n".join(rows) + "\n"


def console(path):
    r = json.load(open(path))
    rows = ["| clients | transport | frames | server -> client p50 / p99 [ms] | the DDS leg alone, server -> bridge, p50 / p99 [ms] | bytes/s per client | bridge CPU [% of one core] |",
            "|---|---|---|---|---|---|---|"]
    for plain, tls in (("one", "tls_one"), ("four", "tls_four")):
        for k, name in ((plain, "ws"), (tls, "wss")):
            if k not in r:
                continue
            x = r[k]
            rows.append(f"| {x['clients']} WebSocket client{'s' if x['clients'] > 1 else ''} | {name} | {x['frames']} | {x['delay_ms']['p50']:.2f} / {x['delay_ms']['p99']:.2f} | "
                        f"{x['dds_leg_ms']['p50']:.2f} / {x['dds_leg_ms']['p99']:.2f} | {x['bytes_per_s_per_client'] / 1000:.0f} kB/s | {100 * x['bridge_cpu_fraction_of_one_core']:.1f} |")
    for k, name in (("page", "http, ws"), ("tls_page", "https, wss")):
        if k in r:
            p = r[k]
            rows.append(f"| the page in headless Chromium (software WebGL) | {name} | {p['frames']} | {p['delay_ms']['p50']:.1f} / {p['delay_ms']['p99']:.1f} | | | |")
    return f"Run of {r['date_utc']} UTC (`bench/console.sh {r['seconds']:g}`), {r['machine']}:\n\n" + "\n".join(rows) + "\n"


def main(root):
    doc_path = os.path.join(root, "docs", "PERFORMANCE.md")
    doc = open(doc_path).read()
    results = os.path.join(root, "bench", "results")
    for name, file, fn in [("tissue", "tissue", tissue), ("tick", "tick", tick), ("materials", "tick", materials), ("haptics", "haptics", haptics),
                           ("soak", "soak", soak), ("record", "record", record), ("console", "console", console)]:
        path = os.path.join(results, f"{file}.json")
        if not os.path.exists(path):
            continue
        table = fn(path)
        if table is None:
            continue
        pattern = re.compile(rf"(<!-- begin {name} -->\n).*?(<!-- end {name} -->)", re.S)
        if not pattern.search(doc):
            print(f"performance_tables: no markers for {name} in {doc_path}", file=sys.stderr)
            continue
        doc = pattern.sub(lambda m: m.group(1) + table + m.group(2), doc)
    open(doc_path, "w").write(doc)
    print(f"performance_tables: wrote {doc_path}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
