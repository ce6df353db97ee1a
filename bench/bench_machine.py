"""The machine a benchmark ran on, as its results record it."""
import os
import platform


def machine():
    """CPU model, core count and memory in GB."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            for line in info:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(),
            "memory_gb": round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1)}


def write_results(out, rows, title, method, header, row_cells):
    """OUT.json (the machine and every row) and OUT.md: a title, the machine and `method`, then a
    table of `header` (column names) with one line a row, `row_cells(row)` its cells."""
    import json
    info = machine()
    with open(out + ".json", "w") as out_file:
        json.dump({"machine": info, "rows": rows}, out_file, indent=1)
    with open(out + ".md", "w") as md:
        md.write(f"# {title}\n\nMachine: {info['cpu']}, {info['cores']} cores, {info['memory_gb']} GB. {method}\n\n")
        md.write("| " + " | ".join(header) + " |\n|" + "---|" * len(header) + "\n")
        for row in rows:
            md.write("| " + " | ".join(str(cell) for cell in row_cells(row)) + " |\n")
