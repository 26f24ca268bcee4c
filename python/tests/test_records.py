"""Records from files (CSV, .mat, a lab's layout) and from numpy arrays; errors naming the
file, row and column."""

import numpy as np
import pytest

import stf_lab


def test_a_bundled_csv_reads_into_numpy_columns(repo):
    rec = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    assert rec.signals == ["t", "x", "phi", "f_stf"]
    assert rec.x.dtype == np.float64 and len(rec.x) == len(rec.t) == len(rec)
    assert rec.u is None and rec.omega is None
    assert rec.t[0] == 0.0 and rec.rate == pytest.approx(200.0)
    # The arrays own the reader's buffers and are read-only.
    assert rec.x.flags.owndata or rec.x.base is not None
    with pytest.raises(ValueError):
        rec.x[0] = 1.0
    assert "power_law_sweep.csv" in repr(rec) and "200 Hz" in repr(rec)


def test_a_mat_file_reads_like_a_csv(repo):
    rec = stf_lab.read_record("core/tests/data/small_record.mat")
    assert len(rec) > 0 and np.all(np.diff(rec.t) > 0)


def test_to_pandas_has_a_column_per_signal(repo):
    df = stf_lab.read_record("experiments/records/power_law_sweep.csv").to_pandas()
    assert list(df.columns) == ["t", "x", "phi", "f_stf"]
    assert len(df) == 12001


def test_from_arrays_applies_units_and_a_rate():
    rec = stf_lab.Record.from_arrays(x=[1.0, 2.0, 3.0], phi=[0.0, 90.0, 180.0], rate=100.0,
                                     units={"x": "mm", "phi": "deg"})
    np.testing.assert_allclose(rec.t, [0.0, 0.01, 0.02])
    np.testing.assert_allclose(rec.x, [1e-3, 2e-3, 3e-3])
    np.testing.assert_allclose(rec.phi, [0.0, np.pi / 2, np.pi])


def test_a_bad_cell_names_file_row_and_column(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,phi\n0,0,0\n0.001,oops,0\n")
    with pytest.raises(stf_lab.RecordError) as e:
        stf_lab.read_record(bad)
    assert str(e.value) == f"{bad}:row 3, column `x`: not a number: `oops`"
    assert isinstance(e.value, stf_lab.StfLabError)


def test_arrays_that_break_the_contract_are_refused():
    with pytest.raises(stf_lab.RecordError, match="column `t`"):
        stf_lab.Record.from_arrays(t=[0.0, 0.0, 1.0], x=[0.0, 0.0, 0.0], phi=[0.0, 0.1, 0.2])
    with pytest.raises(stf_lab.RecordError, match="units.x"):
        stf_lab.Record.from_arrays(x=[1.0], phi=[0.0], rate=1.0, units={"x": "furlong"})
    with pytest.raises(stf_lab.RecordError, match="no `t` column and no sample `rate`"):
        stf_lab.Record.from_arrays(x=[1.0], phi=[0.0])


def test_a_lab_layout_is_read_with_an_experiments_data_keys(tmp_path):
    (tmp_path / "rig.csv").write_text("time_ms,angle_deg,disp_mm\n0,0,1.5\n10,90,2.5\n")
    exp = stf_lab.Experiment.build(
        tmp_path,
        data={"file": "rig.csv", "columns": {"t": "time_ms", "phi": "angle_deg", "x": "disp_mm"},
              "units": {"t": "ms", "phi": "deg", "x": "mm"}},
    )
    rec = stf_lab.read_record(tmp_path / "rig.csv", exp)
    np.testing.assert_allclose(rec.t, [0.0, 0.01])
    np.testing.assert_allclose(rec.x, [1.5e-3, 2.5e-3])


def test_a_saved_record_reads_back_to_the_same_doubles(repo, tmp_path):
    rec = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    back = stf_lab.read_record(rec.save_csv(tmp_path / "copy.csv"))
    assert back.signals == rec.signals
    for name in rec.signals:
        np.testing.assert_array_equal(getattr(back, name), getattr(rec, name))
