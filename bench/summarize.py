#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Summarises tissue_bench JSON: per model and mesh, ns per tet (median of repetitions), tet
updates per second per core, the GPS / corotational speed ratio, and the distance to the memory
bandwidth limit measured in the same run."""
import json
import sys

GPS_BYTES_PER_TET = 296  # GpsModel::Block per lane: 4 int32 + 6+6+21+2 doubles

def main(path):
    data = json.load(open(path))
    med = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        med[b["run_name"]] = b
    ctx = data["context"]
    caches = ", ".join(f"L{c['level']} {c['size']//1024} KiB" for c in ctx.get("caches", []))
    print(f"machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz" + (f", caches {caches}" if caches else ", caches not reported"))
    meshes = ["liver2_1.5k", "liver2_12k", "liver2_96k"]
    models = ["gps", "gps_energy", "gps_large_strain", "corotational", "linear"]
    for kind in ["Force", "Step"]:
        print(f"\n{kind}: ns per tet (median) and tet updates per second per core\n")
        print("| mesh | tets | " + " | ".join(models) + " | gps / corotational speed-up |")
        print("|---|---|" + "---|" * (len(models) + 1))
        for m in meshes:
            row = []
            ns = {}
            tets = None
            for model in models:
                b = med.get(f"{kind}/{model}/{m}")
                if not b:
                    row.append("-")
                    continue
                ns[model] = b["ns_per_tet"] * 1e9 if b["ns_per_tet"] < 1e-3 else b["ns_per_tet"]
                tets = int(b["tets"])
                row.append(f"{ns[model]:.1f} ns ({b['tet_updates_per_s']/1e6:.1f} M/s)")
            ratio = ns["corotational"] / ns["gps"] if "gps" in ns and "corotational" in ns else float("nan")
            print(f"| {m} | {tets} | " + " | ".join(row) + f" | {ratio:.1f}x |")
    print("\nViscoelastic step (3 memory variables) / elastic step, same mesh:")
    print("The last column: the model the bundled scenes run (energy form, volume term 0.5, the same")
    print("memory), the explicit sub-step a server tick repeats (data/scenes, docs/SCENE.md).")
    print()
    print("| mesh | gps step | gps_visco3 step | ratio | scene model step |")
    print("|---|---|---|---|---|")
    for m in meshes:
        a, b, c = med.get(f"Step/gps/{m}"), med.get(f"Step/gps_visco3/{m}"), med.get(f"Step/scene/{m}")
        if a and b:
            scene = f"{c['real_time']:.1f} us" if c else "-"
            print(f"| {m} | {a['real_time']:.1f} us | {b['real_time']:.1f} us | {b['real_time']/a['real_time']:.2f}x | {scene} |")
    print("\nMemory limit for the GPS force loop (296 bytes streamed per tet):\n")
    print("| working set | read bandwidth | limit ns/tet | gps ns/tet | gps / limit |")
    print("|---|---|---|---|---|")
    for m in meshes:
        bw = med.get(f"ReadBandwidth/{m}")
        g = med.get(f"Force/gps/{m}")
        if not bw or not g:
            continue
        gbs = bw["bytes_per_second"] / 1e9
        limit = GPS_BYTES_PER_TET / gbs
        gns = g["ns_per_tet"] * 1e9 if g["ns_per_tet"] < 1e-3 else g["ns_per_tet"]
        print(f"| {m} | {gbs:.1f} GB/s | {limit:.1f} | {gns:.1f} | {gns/limit:.1f}x |")
    print("\nThe strain at an instrument, one 2 cm ball (the server spreads it over a 20 ms window):\n")
    print("| mesh | tetrahedra in the ball | one ball | per tetrahedron |")
    print("|---|---|---|---|")
    for m in meshes:
        t = med.get(f"TipStrain/{m}")
        if t:
            per = t["ns_per_element"] * 1e9 if t["ns_per_element"] < 1e-3 else t["ns_per_element"]
            print(f"| {m} | {int(t['elements'])} | {t['real_time']:.1f} us | {per:.0f} ns |")
    bw = med.get("ReadBandwidth/256MiB")
    if bw:
        print(f"\nDRAM streaming read (256 MiB): {bw['bytes_per_second']/1e9:.1f} GB/s")

if __name__ == "__main__":
    main(sys.argv[1])
