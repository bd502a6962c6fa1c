"""``recipdyn sense RUN.nc -o OUT.nc``: add the channels a monitoring system would record."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app, refused_leaves_nothing, report, with_json

_NONE = ("none", "off")


def _quantity(name: str, text: str | None, unit: str, default):
    """An option's value in SI: ``default`` when not given, None for 'none'/'off'."""
    if text is None:
        return default
    if text.strip().lower() in _NONE:
        return None
    try:  # a bare number is in SI already (and needs no unit registry)
        return float(text)
    except ValueError:
        pass
    from ..units import to_si

    return to_si(name, text, unit=unit)


def _db(name: str, text: str | None, default):
    """A ratio in dB ('40', '40dB', '40 dB'; 'none': no noise)."""
    from ..errors import ParameterError

    if text is None:
        return default
    body = text.strip()
    if body.lower() in _NONE:
        return None
    if body.lower().endswith("db"):
        body = body[:-2].strip()
    try:
        return float(body)
    except ValueError:
        raise ParameterError(f"{name}: {text!r}; allowed: a ratio in dB, e.g. 40dB, or none") \
            from None  # fmt: skip


def _bits(name: str, text: str | None, default):
    from ..errors import ParameterError

    if text is None:
        return default
    if text.strip().lower() in _NONE:
        return None
    try:
        return int(text)
    except ValueError:
        raise ParameterError(f"{name} = {text!r}; allowed: an integer in [2, 32] or none") \
            from None  # fmt: skip


@app.command()
@with_json
def sense(
    run: Path = typer.Argument(..., help="A run from 'recipdyn simulate' (NetCDF)."),
    out: Path = typer.Option(..., "--out", "-o", help="Record to write (.nc, .csv, .mat, .zarr)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the sensors' noise."),
    source: str = typer.Option(
        "a", "--source", help="Recorded acceleration the accelerometer is mounted on."
    ),  # fmt: skip
    location: str = typer.Option("crosshead guide", "--location", help="Label: where it is."),
    resonance: str = typer.Option(
        None, "--resonance", help="Mounting resonance, e.g. 4kHz (default 4 kHz), or none."
    ),  # fmt: skip
    damping: float = typer.Option(0.05, "--damping", help="Damping ratio of the resonance."),
    highpass: str = typer.Option(
        None, "--highpass", help="High-pass corner (default 1 Hz) or none."
    ),  # fmt: skip
    lowpass: str = typer.Option(None, "--lowpass", help="Low-pass corner (default 0.4 fs)."),
    snr: str = typer.Option(
        None, "--snr", help="Signal-to-noise ratio, e.g. 30dB (default), or none."
    ),  # fmt: skip
    full_scale: str = typer.Option(
        None, "--full-scale", help="ADC range +-, e.g. '490 m/s^2' (default 500 g)."
    ),  # fmt: skip
    bits: str = typer.Option(None, "--bits", help="ADC bits (default 16) or none."),
    response: str = typer.Option(
        "exact",
        "--response",
        help="exact (default: the continuous-time response at every frequency) or bilinear "
        "(the resonance and filters discretised, as before 0.x; warped near fs/2).",
    ),  # fmt: skip
    accel: bool = typer.Option(True, "--accel/--no-accel", help="Record the accelerometer."),
    pressure: bool = typer.Option(
        True,
        "--pressure/--no-pressure",
        help="Record a pressure transducer per chamber (when the record has p_head, p_crank).",
    ),  # fmt: skip
    pressure_snr: str = typer.Option(None, "--pressure-snr", help="Default 60dB."),
    pressure_lowpass: str = typer.Option(None, "--pressure-lowpass", help="Default 0.4 fs."),
    pressure_full_scale: str = typer.Option(
        None,
        "--pressure-full-scale",
        help="ADC range 0..FS, e.g. '10 bar' (default: 1-2-5 series above 1.25 x the peak).",
    ),  # fmt: skip
    pressure_bits: str = typer.Option(None, "--pressure-bits", help="Default 16."),
    tacho: bool = typer.Option(
        True, "--tacho/--no-tacho", help="Record a once-per-revolution tacho from theta1."
    ),  # fmt: skip
) -> None:
    """Add sensor channels (accelerometer, pressure transducers, tacho) to a simulated record.

    The channels carry their units and every sensor setting (attributes sensor_*); analyze
    them like a measured record: recipdyn analyze OUT.nc -c accel_guide --tacho tacho"""
    from ..chain import SENSE_DEFAULT
    from ..errors import ParameterError
    from ..io import check_output
    from ..sensors import Accelerometer, PressureTransducer, Tacho

    # every option is checked before the record is read or anything is written
    if not run.exists():
        raise ParameterError(f"run file not found: {run}")
    if run.suffix.lower() != ".nc":
        raise ParameterError(f"input {run}: sense reads a run of 'recipdyn simulate' (.nc); "
                             "a measured signal is analysed as it is: recipdyn analyze "
                             f"{run}")  # fmt: skip
    if not (accel or pressure or tacho):
        raise ParameterError("sensors: --no-accel, --no-pressure and --no-tacho leave nothing "
                             "to record; allowed: at least one sensor")  # fmt: skip
    a0, p0 = SENSE_DEFAULT.accelerometer, SENSE_DEFAULT.pressure  # inside the data set's ranges
    acc = Accelerometer(
        source=source, location=location, response=response,
        resonance_hz=_quantity("resonance", resonance, "Hz", a0.resonance_hz),
        damping=damping, highpass_hz=_quantity("highpass", highpass, "Hz", a0.highpass_hz),
        lowpass_hz=_quantity("lowpass", lowpass, "Hz", a0.lowpass_hz),
        snr_db=_db("snr", snr, a0.snr_db),
        full_scale=_quantity("full_scale", full_scale, "m/s**2", a0.full_scale),
        bits=_bits("bits", bits, a0.bits),
    ) if accel else None  # fmt: skip
    pres = PressureTransducer(
        response=response,
        lowpass_hz=_quantity("pressure_lowpass", pressure_lowpass, "Hz", p0.lowpass_hz),
        snr_db=_db("pressure_snr", pressure_snr, p0.snr_db),
        full_scale=_quantity("pressure_full_scale", pressure_full_scale, "Pa", p0.full_scale),
        bits=_bits("pressure_bits", pressure_bits, p0.bits),
    )  # fmt: skip
    with refused_leaves_nothing(out):  # a refusal found in the record leaves no folder
        check_output(out)
        from ..io import read_dataset, write_dataset
        from ..sensors import record

        ds = read_dataset(run, expected="a recipdyn run (NetCDF from 'recipdyn simulate')")
        if not str(ds.attrs.get("title", "")).startswith("recipdyn simulation"):
            raise ParameterError(f"input {run}: not a run of 'recipdyn simulate' (no model "
                                 "recorded); sense makes sensor channels from a simulated "
                                 f"record; a measured signal is analysed as it is: recipdyn "
                                 f"analyze {run}")  # fmt: skip
        has_p = any(n in ds.data_vars for n in pres.sources)
        res = record(ds, accelerometer=acc, pressure=pres if pressure and has_p else None,
                     tacho=Tacho() if tacho and "theta1" in ds.data_vars else None,
                     seed=seed)  # fmt: skip
        write_dataset(res, out)
    chans = res.attrs["sensor_channels"]
    typer.echo(f"wrote {out}: channels {chans} ({res.sizes['time']} samples at "
               f"{res.attrs['sensor_fs_hz']:g} Hz, seed {seed})")  # fmt: skip
    err = res[acc.name].attrs.get("sensor_resonance_flank_error", 0.0) if acc else 0.0
    if err > 0.01:
        typer.echo(f"note: {acc.name}: the resonance at {acc.resonance_hz:g} Hz lies at "
                   f"{acc.resonance_hz / res.attrs['sensor_fs_hz']:.2g} fs: below f_n/2 the "
                   f"recorded magnitude is off the closed form by up to {err:.1%} (frequency "
                   "warping); simulate at >= 10 f_n for 2 %")  # fmt: skip
    for ch in chans.split(","):
        clipped = res[ch].attrs.get("sensor_clipped_samples", 0)
        if clipped:
            a = res[ch].attrs
            typer.echo(f"warning: {ch}: {clipped} sample(s) clipped at the ADC's range "
                       f"{a['sensor_adc_range']} (its input spans {a['sensor_adc_input_min']:.4g}"
                       f"..{a['sensor_adc_input_max']:.4g}); a larger full scale records "
                       "them")  # fmt: skip
    report(output=str(out), channels=chans.split(","), seed=seed)
