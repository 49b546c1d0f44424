"""clip-value with a tiny random CLIP model (weights, tokenizer and processor built here)."""

from __future__ import annotations

import pytest

from rover.errors import InputError
from rover.methods import get_method
from rover.methods.clip_value import ClipValue


@pytest.fixture(scope="module")
def tiny_clip(tmp_path_factory):
    pytest.importorskip("torch")
    transformers = pytest.importorskip("transformers")
    tokenizers = pytest.importorskip("tokenizers")
    path = tmp_path_factory.mktemp("tiny-clip")

    tok = tokenizers.Tokenizer(tokenizers.models.WordLevel(unk_token="[UNK]"))
    tok.pre_tokenizer = tokenizers.pre_tokenizers.Whitespace()
    trainer = tokenizers.trainers.WordLevelTrainer(special_tokens=["[PAD]", "[UNK]", "[EOS]"])
    tok.train_from_iterator(["pick the can and place it in the bin", "open the door"], trainer)
    fast = transformers.PreTrainedTokenizerFast(
        tokenizer_object=tok, unk_token="[UNK]", pad_token="[PAD]", eos_token="[EOS]"
    )
    fast.save_pretrained(path)
    config = transformers.CLIPConfig(
        text_config={
            "vocab_size": tok.get_vocab_size(),
            "hidden_size": 16,
            "intermediate_size": 32,
            "num_hidden_layers": 1,
            "num_attention_heads": 2,
            "max_position_embeddings": 32,
            "eos_token_id": tok.token_to_id("[EOS]"),
            "pad_token_id": 0,
        },
        vision_config={
            "hidden_size": 16,
            "intermediate_size": 32,
            "num_hidden_layers": 1,
            "num_attention_heads": 2,
            "image_size": 32,
            "patch_size": 8,
        },
        projection_dim=8,
    )
    transformers.CLIPModel(config).save_pretrained(path)
    transformers.CLIPImageProcessor(
        size={"shortest_edge": 32}, crop_size={"height": 32, "width": 32}
    ).save_pretrained(path)
    return path


@pytest.mark.hf
@pytest.mark.slow
async def test_clip_value_runs_offline(make_episode, tiny_clip):
    ep = make_episode(6)
    trace = await get_method("clip-value", model_path=tiny_clip).run(ep, None)
    p = trace.progress()
    assert len(p) == 6 and p[0] == 0 and all(0 <= v <= 100 for v in p)
    assert max(p) in (0, 100)  # rescaled per video: the most task-like frame is 100
    assert trace.totals.calls == 0 and trace.backend == "embedding"
    again = await get_method("clip-value", model_path=tiny_clip).run(ep, None)
    assert again.progress() == p


def test_to_progress_rescaling():
    import numpy as np

    assert ClipValue.to_progress(np.array([0.2, 0.1, 0.4, 0.3])) == pytest.approx([0, 0, 100, 50])
    assert ClipValue.to_progress(np.array([0.5, 0.5])) == [0, 0]


async def test_clip_value_needs_a_model(make_episode, tmp_path):
    with pytest.raises(InputError, match="model_path"):
        await get_method("clip-value").run(make_episode(3), None)
    with pytest.raises(InputError, match="does not exist"):
        await get_method("clip-value", model_path=tmp_path / "nope").run(make_episode(3), None)


@pytest.mark.hf
@pytest.mark.slow
def test_clip_value_through_rover_eval(make_episode, tiny_clip, tmp_path):
    """`rover eval --methods clip-value --model-path` scores the embedding baseline too."""
    import json

    from typer.testing import CliRunner

    from rover.cli import app
    from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode

    ds = tmp_path / "ds"
    write_dataset_info(ds, DatasetInfo(name="t", views=["left"]))
    write_episode(ds, make_episode(6, episode_id="a"))
    out = tmp_path / "run"
    args = ["eval", "--dataset", str(ds), "--methods", "clip-value,rover", "--out", str(out)]
    args += ["--backend", "oracle"]
    missing = CliRunner().invoke(app, args)
    assert missing.exit_code != 0 and "--model-path" in str(missing.exception or missing.output)
    done = CliRunner().invoke(app, [*args, "--model-path", str(tiny_clip)])
    assert done.exit_code == 0, done.output
    rows = json.loads((out / "metrics.json").read_text())["per_trace"]
    assert {r["method"] for r in rows} == {"clip-value", "rover"}
    clip = next(r for r in rows if r["method"] == "clip-value")
    assert clip["calls"] == 0
