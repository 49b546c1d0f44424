"""The hf backend on a tiny random Qwen-VL model built here and loaded the real way."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from rover.errors import InputError
from rover.vlm import BackendConfig, load_vlm

pytestmark = [pytest.mark.hf, pytest.mark.slow]

torch = pytest.importorskip("torch")
transformers = pytest.importorskip("transformers")
tokenizers = pytest.importorskip("tokenizers")

SPECIAL = [
    "<|endoftext|>",
    "<|im_start|>",
    "<|im_end|>",
    "<|vision_start|>",
    "<|vision_end|>",
    "<|image_pad|>",
    "<|video_pad|>",
]
WORDS = (
    "system user assistant you watch robot videos describe the frame gripper is open closed "
    "holding can lifted frame description subtask completion percentage 10% 50% 100%"
)
# a Qwen-style chat template: one <|vision_start|><|image_pad|><|vision_end|> per image
TEMPLATE = (
    "{% for m in messages %}<|im_start|> {{ m['role'] }} "
    "{% if m['content'] is string %}{{ m['content'] }} {% else %}{% for c in m['content'] %}"
    "{% if c['type'] == 'image' %}<|vision_start|><|image_pad|><|vision_end|> "
    "{% else %}{{ c['text'] }} {% endif %}{% endfor %}{% endif %}<|im_end|> {% endfor %}"
    "{% if add_generation_prompt %}<|im_start|> assistant {% endif %}"
)


def _tokenizer():
    from tokenizers import Tokenizer, decoders, models, pre_tokenizers, trainers

    tok = Tokenizer(models.WordLevel(unk_token="[UNK]"))
    tok.pre_tokenizer = pre_tokenizers.WhitespaceSplit()
    tok.train_from_iterator([WORDS], trainers.WordLevelTrainer(special_tokens=["[UNK]", *SPECIAL]))
    tok.decoder = decoders.WordPiece(prefix="##")  # joins words with spaces
    fast = transformers.PreTrainedTokenizerFast(
        tokenizer_object=tok,
        unk_token="[UNK]",
        eos_token="<|im_end|>",
        pad_token="<|endoftext|>",
        additional_special_tokens=SPECIAL,
    )
    fast.chat_template = TEMPLATE
    return fast


def _image_processor():
    try:
        from transformers.models.qwen2_vl.image_processing_pil_qwen2_vl import (
            Qwen2VLImageProcessorPil as Processor,
        )
    except ImportError:  # older transformers
        from transformers import Qwen2VLImageProcessor as Processor
    # 28 px patches after merging: 64x48 frames -> a handful of visual tokens
    return Processor(min_pixels=28 * 28, max_pixels=56 * 56 * 4, merge_size=2, patch_size=14)


def build_tiny_qwen_vl(out: Path, family: str = "qwen2_vl") -> Path:
    """A one-layer, 32-wide Qwen2-VL or Qwen2.5-VL with a 30-word vocabulary, saved like a
    real checkpoint (config, safetensors, tokenizer, chat template, image processor)."""
    tok = _tokenizer()
    ids = {s: tok.convert_tokens_to_ids(s) for s in SPECIAL}
    text = dict(
        vocab_size=len(tok),
        hidden_size=32,
        intermediate_size=64,
        num_hidden_layers=1,
        num_attention_heads=2,
        num_key_value_heads=1,
        max_position_embeddings=512,
        rope_parameters={"rope_type": "default", "mrope_section": [2, 2, 4], "rope_theta": 1e4},
        bos_token_id=ids["<|im_start|>"],
        eos_token_id=ids["<|im_end|>"],
        pad_token_id=ids["<|endoftext|>"],
    )
    if family == "qwen2_vl":
        vision = dict(depth=1, embed_dim=32, hidden_size=32, num_heads=2, mlp_ratio=2)
        config_cls, model_cls = (
            transformers.Qwen2VLConfig,
            transformers.Qwen2VLForConditionalGeneration,
        )
    else:
        vision = dict(
            depth=1,
            hidden_size=32,
            intermediate_size=64,
            num_heads=2,
            out_hidden_size=32,
            fullatt_block_indexes=[0],
        )
        config_cls = transformers.Qwen2_5_VLConfig
        model_cls = transformers.Qwen2_5_VLForConditionalGeneration
    config = config_cls(
        text_config=text,
        vision_config=vision,
        image_token_id=ids["<|image_pad|>"],
        video_token_id=ids["<|video_pad|>"],
        vision_start_token_id=ids["<|vision_start|>"],
        vision_end_token_id=ids["<|vision_end|>"],
    )
    torch.manual_seed(0)
    model_cls(config).save_pretrained(out)
    tok.save_pretrained(out)
    _image_processor().save_pretrained(out)
    return out


@pytest.fixture(scope="module", params=["qwen2_vl", "qwen2_5_vl"])
def tiny_model(request, tmp_path_factory) -> Path:
    return build_tiny_qwen_vl(tmp_path_factory.mktemp(request.param), request.param)


def test_generates_from_images_with_exact_usage(tiny_model, make_prompt, tmp_path):
    config = BackendConfig(cache_path=tmp_path / "c.sqlite", max_tokens=5, device="cpu")
    vlm = load_vlm(f"hf:{tiny_model}", config)
    prompt = make_prompt(n_images=2)

    completion = asyncio.run(vlm.complete(prompt))

    assert isinstance(completion.text, str) and completion.text
    assert set(completion.text.split()) <= set(WORDS.split())  # decoded from our vocabulary
    assert (completion.backend, completion.model) == ("hf", str(tiny_model))
    usage = completion.usage
    assert usage.source == "reported"
    assert 1 <= usage.completion_tokens <= 5
    # each 64x48 frame is resized to 56x56 (multiples of 28): 4x4 patches, merged 2x2 -> 4
    assert usage.image_tokens == 2 * 4
    assert usage.prompt_tokens > usage.image_tokens

    again = asyncio.run(load_vlm(f"hf:{tiny_model}", config).complete(prompt))
    assert again.cached and again.text == completion.text


@pytest.mark.parametrize("tiny_model", ["qwen2_vl"], indirect=True)
def test_token_rule_override_gives_estimates(tiny_model, make_prompt):
    config = BackendConfig(no_cache=True, max_tokens=3, token_rule="openai-low")
    completion = asyncio.run(load_vlm(f"hf:{tiny_model}", config).complete(make_prompt()))
    assert completion.usage.source == "estimated" and completion.usage.image_tokens == 85


def test_missing_model_folder_is_a_clear_error(tmp_path):
    with pytest.raises(InputError, match="config.json"):
        load_vlm(f"hf:{tmp_path / 'nothing-here'}")
