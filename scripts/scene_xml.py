"""Pieces of Mitsuba 0.6 scene files shared by the scripts that write Tessera's own scenes."""


def write_text(path, text):
    with open(path, "w", encoding="utf-8", newline="\n") as out:
        out.write(text)


def f(v):
    """A number as the scenes write it: at most 4 decimals, no trailing zeros."""
    s = f"{v:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def vec(v):
    return ", ".join(f(c) for c in v)


def sensor(origin, target, fov, spp, width, height):
    """A perspective camera with an independent sampler and a box-filtered film."""
    return f"""    <sensor type="perspective">
        <float name="fov" value="{f(fov)}"/>
        <transform name="toWorld">
            <lookat origin="{vec(origin)}" target="{vec(target)}" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sampleCount" value="{spp}"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{width}"/>
            <integer name="height" value="{height}"/>
            <rfilter type="box"/>
        </film>
    </sensor>
"""
