"""PhantomDataset: exact rates, determinism across workers and ranks, pixels and labels, order with augmentation."""

from __future__ import annotations

import pickle

import pytest
import torch
from torch.utils.data import DataLoader, DistributedSampler

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets import LABEL_KEYS, PhantomDataset, camera_attack_params
from lerobot_phantom.datasets.schedule import attacked_count
from lerobot_phantom.transforms.intensity import interpolate_levels
from lerobot_phantom.transforms.registry import ATTACK_IDS, ATTACK_NAMES, CLEAN_ID

FRONT, WRIST = "observation.images.front", "observation.images.wrist"
# em_truncation is deterministic given its intensity; laser_blinding also draws a random spot position, so
# parameter reproduction is really tested.
ATTACKS = ["em_truncation", "laser_blinding"]


class ArrayDataset(torch.utils.data.Dataset):
    """The LeRobotDataset interface, minus LeRobot: fast enough for thousands of samples."""

    def __init__(self, num_items: int, size: int = 8, image_transforms=None) -> None:
        self.num_items = num_items
        self.size = size
        self.image_transforms = image_transforms

    def __len__(self) -> int:
        return self.num_items

    def __getitem__(self, index: int) -> dict:
        g = torch.Generator().manual_seed(index)
        item = {
            FRONT: torch.rand(3, self.size, self.size, generator=g),
            WRIST: torch.rand(3, self.size, self.size, generator=g),
            "index": torch.tensor(index),
            "task": "pick the cube",
        }
        if self.image_transforms is not None:
            for key in (FRONT, WRIST):
                item[key] = self.image_transforms(item[key])
        return item


def labels_of(dataset: PhantomDataset) -> dict[str, torch.Tensor]:
    items = [dataset[i] for i in range(len(dataset))]
    return {key: torch.stack([item[key] for item in items]) for key in LABEL_KEYS}


def test_attacked_fraction_and_per_attack_counts_are_exact_over_an_epoch():
    dataset = PhantomDataset(
        ArrayDataset(2000, size=4),
        PhantomConfig(rate=0.3, attacks=ATTACKS, weights=[1.0, 3.0]),
        camera_keys=[FRONT, WRIST],
        apply=False,
    )
    for epoch in (0, 1):
        dataset.set_epoch(epoch)
        attack = labels_of(dataset)["phantom.attack"]
        attacked = int((attack != CLEAN_ID).sum())
        assert attacked == attacked_count(0.3, 2000) == 600
        assert abs(attacked / 2000 - 0.3) < 0.01
        assert int((attack == ATTACK_IDS["em_truncation"]).sum()) == 150
        assert int((attack == ATTACK_IDS["laser_blinding"]).sum()) == 450


def test_labels_describe_the_decision_and_intensities_follow_the_config():
    dataset = PhantomDataset(
        ArrayDataset(300),
        PhantomConfig(rate=0.5, attacks=ATTACKS, intensity="0.4:0.6"),
        camera_keys=[FRONT, WRIST],
    )
    labels = labels_of(dataset)
    attacked = labels["phantom.attack"] != CLEAN_ID
    assert torch.all(labels["phantom.camera"][attacked] == 1)  # cameras=[first] -> bit 0
    assert torch.all(labels["phantom.camera"][~attacked] == 0)
    assert torch.all(labels["phantom.intensity"][~attacked] == 0)
    s = labels["phantom.intensity"][attacked]
    assert s.min() >= 0.4 and s.max() <= 0.6
    assert torch.all(labels["phantom.instruction_attack"] == CLEAN_ID)
    assert (
        labels["phantom.attack"].dtype == torch.int64 and labels["phantom.intensity"].dtype == torch.float32
    )
    for i in (0, 17, 299):
        decision = dataset.decision(i)
        assert decision["attack_id"] == int(labels["phantom.attack"][i])
        assert decision["seed"] == int(labels["phantom.seed"][i])


def test_random_intensity_draws_each_attacks_training_distribution():
    """``intensity="random"`` (the default) follows the authors' adversarial training per attack: ultrasound blur
    ``randint(5, 20)`` px, so P(d < 10 px) = 5/16 (a uniform s over weak..strong, the old draw, gives 1/2)."""
    dataset = PhantomDataset(
        ArrayDataset(1600, size=4),
        PhantomConfig(rate=1.0, attacks=["ultrasound_blur"], intensity="random"),
        camera_keys=[FRONT],
        apply=False,
    )
    blur = dataset.attacks["ultrasound_blur"]
    s = torch.tensor([dataset.decision(i)["intensity"] for i in range(len(dataset))])
    displacement = torch.round(interpolate_levels(s, blur.random_parameter.levels))
    assert set(displacement.long().tolist()) == set(range(5, 21))
    # the schedule is stratified: within one item per stratum of the exact 5/16
    assert abs(float((displacement < 10).double().mean()) - 5 / 16) <= 1 / len(dataset)


def test_decision_depends_only_on_seed_epoch_and_index():
    config = PhantomConfig(rate=0.3, attacks=ATTACKS, cameras=["random"], seed=11)
    a = PhantomDataset(ArrayDataset(200), config, camera_keys=[FRONT, WRIST])
    b = PhantomDataset(ArrayDataset(200), config, camera_keys=[FRONT, WRIST], rank=1, world_size=2)
    b.set_epoch(4)
    assert [a.decision(i, epoch=4) for i in range(200)] == [b.decision(i) for i in range(200)]
    a.set_epoch(5)
    assert [a.decision(i) for i in range(200)] != [b.decision(i) for i in range(200)]
    other_seed = PhantomDataset(
        ArrayDataset(200), PhantomConfig(rate=0.3, attacks=ATTACKS, seed=12), camera_keys=[FRONT, WRIST]
    )
    assert [d["attack"] for d in map(other_seed.decision, range(200))] != [
        d["attack"] for d in map(b.decision, range(200))
    ]


def test_ranks_of_a_distributed_sampler_together_attack_exactly_rate():
    config = PhantomConfig(rate=0.3, attacks=ATTACKS)
    seen = {}
    for rank in range(2):
        dataset = PhantomDataset(
            ArrayDataset(101, size=4), config, camera_keys=[FRONT], rank=rank, world_size=2
        )
        sampler = DistributedSampler(
            dataset, num_replicas=2, rank=rank, shuffle=True, seed=0, drop_last=False
        )
        for index in sampler:
            seen[index] = int(dataset[index]["phantom.attack"])
    assert len(seen) == 101
    assert sum(v != CLEAN_ID for v in seen.values()) == attacked_count(0.3, 101)


def test_random_camera_attacks_exactly_one_camera():
    dataset = PhantomDataset(
        ArrayDataset(100),
        PhantomConfig(rate=0.4, attacks=ATTACKS, cameras=["random"]),
        camera_keys=[FRONT, WRIST],
    )
    masks = labels_of(dataset)["phantom.camera"]
    assert set(masks.tolist()) == {0, 1, 2}
    assert int((masks == 1).sum()) == int((masks == 2).sum()) == 20
    everything = PhantomDataset(
        ArrayDataset(50),
        PhantomConfig(rate=0.4, attacks=ATTACKS, cameras=["all"]),
        camera_keys=[FRONT, WRIST],
    )
    assert set(labels_of(everything)["phantom.camera"].tolist()) == {0, 3}


def test_pixels_match_labels_and_clean_cameras_are_untouched():
    source = ArrayDataset(60)
    dataset = PhantomDataset(
        source, PhantomConfig(rate=0.5, attacks=ATTACKS, cameras=["random"]), camera_keys=[FRONT, WRIST]
    )
    reference = PhantomDataset(
        source, PhantomConfig(rate=0.5, attacks=ATTACKS, cameras=["random"]), camera_keys=[FRONT, WRIST]
    )
    changed = 0
    for i in range(len(dataset)):
        item, raw = dataset[i], source[i]
        attack_id, mask = int(item["phantom.attack"]), int(item["phantom.camera"])
        for bit, key in enumerate((FRONT, WRIST)):
            if not mask >> bit & 1 or attack_id == CLEAN_ID:
                assert torch.equal(item[key], raw[key])
                continue
            attack = reference.attacks[ATTACK_NAMES[attack_id]]
            # The device-side reproduction: the labels alone give the pixels back.
            (params,) = camera_attack_params(
                attack, int(item["phantom.seed"]), item["phantom.intensity"], [(8, 8)]
            )
            assert torch.equal(item[key], attack.apply_params(raw[key], params))
            changed += not torch.equal(item[key], raw[key])
    assert changed >= 25  # 30 attacked samples; an attack may leave a tiny frame unchanged only rarely


def test_apply_false_adds_the_same_labels_and_leaves_images_alone():
    source = ArrayDataset(40)
    config = PhantomConfig(rate=0.5, attacks=ATTACKS)
    applied = PhantomDataset(source, config, camera_keys=[FRONT, WRIST])
    labelled = PhantomDataset(source, config, camera_keys=[FRONT, WRIST], apply=False)
    for key, value in labels_of(applied).items():
        assert torch.equal(value, labels_of(labelled)[key])
    for i in range(40):
        assert torch.equal(labelled[i][FRONT], source[i][FRONT])


def test_attack_runs_before_image_transforms_and_the_callers_dataset_is_unchanged():
    seen = []

    def flip_rows(image):  # does not commute with a row truncation
        seen.append(image.clone())
        return image.flip(-2)

    source = ArrayDataset(20, image_transforms=flip_rows)
    config = PhantomConfig(rate=1.0, attacks=["em_truncation"], intensity="strong")
    dataset = PhantomDataset(source, config, camera_keys=[FRONT, WRIST])
    assert source.image_transforms is flip_rows and dataset.dataset.image_transforms is None
    item = dataset[3]
    raw = ArrayDataset(20)[3]
    (params,) = camera_attack_params(
        dataset.attacks["em_truncation"], int(item["phantom.seed"]), 1.0, [(8, 8)]
    )
    attacked = dataset.attacks["em_truncation"].apply_params(raw[FRONT], params)
    assert torch.equal(seen[0], attacked)  # the transform saw the attacked frame
    assert torch.equal(item[FRONT], attacked.flip(-2))
    assert not torch.equal(
        item[FRONT], dataset.attacks["em_truncation"].apply_params(raw[FRONT].flip(-2), params)
    )
    assert torch.equal(item[WRIST], raw[WRIST].flip(-2))  # every camera still gets the augmentation


def test_errors_inside_an_attack_propagate_with_context(monkeypatch):
    dataset = PhantomDataset(
        ArrayDataset(10), PhantomConfig(rate=1.0, attacks=["laser_blinding"]), camera_keys=[FRONT]
    )

    def broken(image, params):
        raise ValueError("boom")

    monkeypatch.setattr(dataset.attacks["laser_blinding"], "_apply", broken)
    dataset.set_epoch(2)
    with pytest.raises(RuntimeError) as info:
        dataset[7]
    notes = "\n".join(getattr(info.value, "__notes__", []))
    assert "sample index 7" in notes and "epoch 2" in notes and "laser_blinding" in notes
    assert "LaserBlinding" in str(info.value)  # the base class names the attack and its parameters
    assert isinstance(info.value.__cause__, ValueError)


def test_dataloader_workers_and_persistent_epochs_give_identical_samples(image_dataset):
    config = PhantomConfig(rate=0.5, attacks=ATTACKS, cameras=["random"], seed=3)
    dataset = PhantomDataset(image_dataset, config)

    def run(num_workers, epochs, persistent=False):
        loader = DataLoader(
            dataset, batch_size=6, shuffle=False, num_workers=num_workers, persistent_workers=persistent
        )
        out = []
        for epoch in epochs:
            dataset.set_epoch(epoch)
            batches = list(loader)
            out.append({key: torch.cat([b[key] for b in batches]) for key in (FRONT, WRIST, *LABEL_KEYS)})
        return out

    serial = run(0, [0, 1])
    parallel = run(2, [0, 1], persistent=True)
    for a, b in zip(serial, parallel, strict=True):
        for key in a:
            assert torch.equal(a[key], b[key]), key
    assert not torch.equal(serial[0]["phantom.attack"], serial[1]["phantom.attack"])
    assert int((serial[0]["phantom.attack"] != CLEAN_ID).sum()) == attacked_count(0.5, len(dataset))


def test_real_lerobot_dataset_clean_frames_bit_identical_and_passthrough(image_dataset):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = PhantomDataset(image_dataset, PhantomConfig(rate=0.5, attacks=ATTACKS, cameras=["all"]))
    assert dataset.meta is image_dataset.meta
    assert dataset.num_frames == image_dataset.num_frames and dataset.features == image_dataset.features
    assert dataset.camera_keys == [FRONT, WRIST]
    fresh = LeRobotDataset(image_dataset.repo_id, root=image_dataset.root)
    attacked = 0
    for i in range(len(dataset)):
        item, raw = dataset[i], fresh[i]
        for key in (FRONT, WRIST):
            if int(item["phantom.attack"]) == CLEAN_ID:
                assert torch.equal(item[key], raw[key])
            else:
                attacked += 1
                assert not torch.equal(item[key], raw[key])
        assert torch.equal(item["action"], raw["action"]) and item["task"] == raw["task"]
    assert attacked == 2 * attacked_count(0.5, len(dataset))
    restored = pickle.loads(pickle.dumps(dataset))
    assert torch.equal(restored[1][FRONT], dataset[1][FRONT])


def test_delta_timestamps_frames_share_one_attack(image_dataset_root):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    delta = {FRONT: [-0.2, -0.1, 0.0]}
    stacked = LeRobotDataset("phantom/tiny", root=image_dataset_root, delta_timestamps=delta)
    single = LeRobotDataset("phantom/tiny", root=image_dataset_root)
    dataset = PhantomDataset(stacked, PhantomConfig(rate=1.0, attacks=["laser_blinding"]))
    checked = 0
    for i in (5, 20, 30):
        item = dataset[i]
        raw = stacked[i][FRONT]
        assert item[FRONT].shape == raw.shape == (3, 3, 32, 32)
        attack = dataset.attacks["laser_blinding"]
        (params,) = camera_attack_params(
            attack, int(item["phantom.seed"]), item["phantom.intensity"], [(32, 32)]
        )
        for t in range(3):
            # Each frame equals that frame attacked alone with the sample's single parameter set.
            assert torch.equal(item[FRONT][t], attack.apply_params(raw[t], params))
            assert not torch.equal(item[FRONT][t], raw[t])
            checked += 1
        assert torch.equal(raw[-1], single[i][FRONT])
    assert checked == 9


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"attacks": ["laser_blinding", "nope"]}, "valid attacks"),
        ({"rate": 1.5}, "[0, 1]"),
        ({"rate": -0.1}, "[0, 1]"),
        ({"instruction_rate": 2.0}, "[0, 1]"),
        ({"attacks": ATTACKS, "weights": [1.0]}, "one weight per attack"),
        ({"attacks": ATTACKS, "weights": [1.0, -1.0]}, ">= 0"),
        ({"attacks": ["em_truncation", "em_truncation"]}, "more than once"),
        ({"instruction_attacks": ["laser_blinding"], "instruction_rate": 0.1}, "instruction attacks only"),
        ({"instruction_rate": 0.2}, "needs --phantom.instruction_attacks"),
        ({"intensity": "loud"}, "valid"),
        ({"cameras": ["all", "observation.images.front"]}, "stand alone"),
        ({"where": "gpu"}, "dataloader"),
    ],
)
def test_bad_configs_name_the_valid_values(kwargs, message):
    with pytest.raises(ValueError, match=None) as info:
        PhantomConfig(**kwargs)
    assert message in str(info.value)


def test_unknown_camera_key_lists_the_datasets_keys():
    with pytest.raises(ValueError) as info:
        PhantomDataset(
            ArrayDataset(4), PhantomConfig(cameras=["observation.images.top"]), camera_keys=[FRONT, WRIST]
        )
    assert (
        FRONT in str(info.value) and WRIST in str(info.value) and "observation.images.top" in str(info.value)
    )


def test_dataset_without_meta_needs_camera_keys():
    with pytest.raises(ValueError, match="camera_keys"):
        PhantomDataset(ArrayDataset(4), PhantomConfig())


def test_instruction_channel_is_independent_and_exact():
    source = ArrayDataset(200, size=4)
    config = PhantomConfig(
        rate=0.3,
        attacks=["em_truncation"],
        instruction_attacks=["voice_dos", "voice_spoofing"],
        instruction_rate=0.2,
    )
    dataset = PhantomDataset(source, config, camera_keys=[FRONT])
    labels = labels_of(dataset)
    instruction = labels["phantom.instruction_attack"]
    assert int((instruction != CLEAN_ID).sum()) == 40
    assert set(instruction.tolist()) == {CLEAN_ID, ATTACK_IDS["voice_dos"], ATTACK_IDS["voice_spoofing"]}
    assert int((labels["phantom.attack"] != CLEAN_ID).sum()) == 60
    for i in range(200):
        task = dataset[i]["task"]
        assert (task != "pick the cube") == (int(instruction[i]) != CLEAN_ID)


def test_instruction_attack_in_the_main_channel_attacks_the_task_not_a_camera():
    source = ArrayDataset(50, size=4)
    dataset = PhantomDataset(
        source, PhantomConfig(rate=0.4, attacks=["voice_dos", "em_truncation"]), camera_keys=[FRONT]
    )
    dos = 0
    for i in range(50):
        item = dataset[i]
        if int(item["phantom.attack"]) == ATTACK_IDS["voice_dos"]:
            dos += 1
            assert int(item["phantom.camera"]) == 0
            assert item["task"] != "pick the cube"
            assert torch.equal(item[FRONT], source[i][FRONT])
        elif int(item["phantom.attack"]) == ATTACK_IDS["em_truncation"]:
            assert int(item["phantom.camera"]) == 1 and item["task"] == "pick the cube"
    assert dos == 10
